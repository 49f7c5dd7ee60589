"""Simulation experiments: ``tafel match`` and its GameController, scenario runs, batch replays, the
program stepped in this process, rendered scenes with ground truth and the classifier trained on them."""
