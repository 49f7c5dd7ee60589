"""Test-suite settings: hypothesis runs without deadlines, because these machines are noisy and
timing belongs in benchmarks, not in tests."""

from __future__ import annotations

from hypothesis import HealthCheck, settings

settings.register_profile("tafel", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("tafel")
