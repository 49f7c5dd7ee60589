"""Watching a program: the web view (RobotControl in the browser), Foxglove live and in recordings,
the feed that hands them copies, the console, and TeamControl (``tafel team``)."""
