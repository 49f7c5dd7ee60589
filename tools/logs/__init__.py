"""Recorded logs: ``tafel log info``, ``export``, ``slice``, ``convert`` and ``compare``."""
