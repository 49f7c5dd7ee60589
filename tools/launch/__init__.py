"""Launching a program: building it from configuration, its debug server and viewers, recording,
``--watch``, and running it (``tafel run``). Below the command line; above the viewers."""
