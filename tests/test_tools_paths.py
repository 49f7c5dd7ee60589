"""Paths the tools find relative to their own files: moving a file into a wing (tools/robot/,
tools/simulation/) moves its idea of where the project is, so each is checked to lead somewhere real."""

from __future__ import annotations

from pathlib import Path

REPO = Path(__file__).resolve().parent.parent


def test_deploy_builds_from_the_project_and_ships_the_configuration_and_the_robot_script() -> None:
    from tafel.tools.robot import deploy

    assert deploy.REPOSITORY == REPO and (deploy.REPOSITORY / "pyproject.toml").is_file()
    assert (deploy.DEFAULT_CONFIG / "general.toml").is_file()
    assert deploy.ROBOT_SCRIPT.is_file()


def test_the_launch_defaults_name_the_shipped_configuration() -> None:
    from tafel.tools.launch.defaults import DEFAULT_CONFIG

    assert DEFAULT_CONFIG == REPO / "config" and (DEFAULT_CONFIG / "general.toml").is_file()


def test_the_classifier_trainer_finds_the_checkouts_real_images() -> None:
    from tafel.tools.simulation import train_ball_classifier

    assert train_ball_classifier.DEFAULT_REAL == REPO / "tests" / "data" / "real_images"
    assert train_ball_classifier.DEFAULT_REAL.is_dir()
