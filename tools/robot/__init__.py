"""The real robot: ``tafel robots`` and ``tafel deploy`` (with ``deploy_robot.sh``, run on the robot)."""
