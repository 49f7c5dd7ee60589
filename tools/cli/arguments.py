"""The command lines of ``tafel`` and its subcommands: argparse only, so that building the parser is cheap.

``tafel --help``, ``tafel console`` and ``tafel log info`` build the whole parser; the code that runs a
command (MuJoCo for ``match``, the scenario runner, protobuf for logs) is imported by that command alone
(``COMMANDS`` in ``dispatch.py`` names it; it is loaded when it runs). Keep the imports here to the
standard library and the tools' modules of constants (``launch/defaults.py``, ``simulation/rules.py``).
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path
from typing import Any

from tafel.tools.launch.defaults import DEFAULT_DEBUG_PORT, DEFAULT_FOXGLOVE_PORT, DEFAULT_WEB_PORT
from tafel.tools.simulation.rules import MAX_PLAYERS_PER_TEAM

#: the factors ``--speed`` takes: slower than a thousandth of real time no frame would ever come
SPEED_RANGE = (0.001, 1000.0)


def parse_speed(text: str) -> float | None:
    """``--speed``: a factor against the wall clock, or ``max`` (None: as fast as possible)."""
    if text == "max":
        return None
    from tafel.core.framework.values import convert  # when a value is read, not at import: tafel --help stays light

    low, high = SPEED_RANGE
    return convert(text, float, where="--speed", bounds=SPEED_RANGE, text=True, expected=f"a factor from {low:g} to {high:g} or 'max'",
                   error=argparse.ArgumentTypeError)


def positive(kind: type) -> Any:
    """An argparse type accepting numbers of ``kind`` greater than zero."""

    def parse(text: str) -> Any:
        from tafel.core.framework.values import Range, convert

        return convert(text, kind, where="", bounds=Range(0, low_open=True), text=True, error=argparse.ArgumentTypeError)

    return parse


def port_number(text: str) -> int:
    """A TCP port: 0 (any free one) to 65535."""
    from tafel.core.framework.values import convert

    return convert(text, int, where="", bounds=(0, 65535), text=True, expected="a port number from 0 to 65535 (0: any free one)",
                   error=argparse.ArgumentTypeError)


def context_name(text: str) -> str:
    """A context's name, as written: cognition or motion."""
    from tafel.core.framework.contexts import Context

    return Context.of(text, "", argparse.ArgumentTypeError).value


def add_module_arguments(parser: argparse.ArgumentParser) -> None:
    """``--add-module``, ``--remove-module`` (``CONTEXT:MODULE``) and ``--module-path``: the program's modules
    changed on the command line, alike for ``run``, ``scenarios run`` and ``replay-batch``."""
    parser.add_argument("--add-module", action="append", default=[], metavar="CONTEXT:MODULE",
                        help="add a module to a context's list, e.g. cognition:SimpleBallModeler (repeatable)")
    parser.add_argument("--remove-module", action="append", default=[], metavar="CONTEXT:MODULE",
                        help="remove a module from a context's list (repeatable)")
    add_module_path_argument(parser)


def add_module_path_argument(parser: argparse.ArgumentParser) -> None:
    """``--module-path DIR``: folders of module files of one's own, imported at start (repeatable)."""
    parser.add_argument("--module-path", dest="module_path", action="append", default=[], type=Path, metavar="DIR",
                        help="import the module files (*.py) in DIR, so that configuration can name their modules "
                             "(repeatable; installed packages announce theirs in the entry point group tafel.modules)")


def parse_teams(text: str) -> tuple[int, int]:
    """``--teams``: NvM with N, M from 0 to 5 and at least one robot, e.g. 2v2 or 1v0."""
    match = re.fullmatch(r"(\d)v(\d)", text.strip().lower())
    if not match or int(match[1]) > MAX_PLAYERS_PER_TEAM or int(match[2]) > MAX_PLAYERS_PER_TEAM or match[1] == match[2] == "0":
        raise argparse.ArgumentTypeError(f"--teams takes NvM with 0 to {MAX_PLAYERS_PER_TEAM} robots a team (1v1, 2v2, 5v5, 1v0), got {text!r}")
    return int(match[1]), int(match[2])


#: the free kicks the simulated referee can be told to call (``--call``)
CALLABLE_SET_PLAYS = ("kick_in", "goal_kick", "corner_kick", "pushing_free_kick")


def parse_call(text: str) -> tuple[float, str, int]:
    """``--call``: SECONDS:SET_PLAY:TEAM, e.g. 20:kick_in:2."""
    parts = text.strip().lower().split(":")
    try:
        seconds, set_play, team = float(parts[0]), parts[1], int(parts[2])
        if len(parts) != 3 or seconds < 0 or set_play not in CALLABLE_SET_PLAYS or team not in (1, 2):
            raise ValueError(text)
    except (ValueError, IndexError):
        raise argparse.ArgumentTypeError(f"--call takes SECONDS:SET_PLAY:TEAM with SET_PLAY one of {', '.join(CALLABLE_SET_PLAYS)} "
                                         f"and TEAM 1 or 2 (e.g. 20:kick_in:2), got {text!r}") from None
    return seconds, set_play, team


#: tafel match --realism: ``platforms.realism.LEVELS``, named here so that building the parser imports no OpenCV
REALISM_LEVELS = ("off", "mild", "full")


def add_match_command(commands: Any) -> None:
    from tafel.core.runtime.platform import seed_number

    match = commands.add_parser("match", help="play a simulated game: several robots in MuJoCo, refereed by a simulated GameController")
    match.add_argument("--teams", type=parse_teams, default=(1, 1), metavar="NvM", help="robots per team, 1v1 to 5v5 or e.g. 1v0 (default 1v1)")
    match.add_argument("--seconds", type=positive(float), default=600.0, help="playing time of the whole game, both halves (default 600)")
    match.add_argument("--cameras", choices=["on", "off"], default="on",
                       help="on: every robot renders its cameras and sees through them; off: perception from ground truth")
    match.add_argument("--speed", type=parse_speed, default=1.0, help="pace against the wall clock: a factor, or 'max'")
    match.add_argument("--seed", type=seed_number, default=0, help="seed of every robot's sensor noise")
    match.add_argument("--realism", nargs="?", const="full", default="off", choices=REALISM_LEVELS, metavar="LEVEL",
                       help="every robot's cameras deliver what a real NAO camera would, each seeded by its own seed, in one "
                            "realistic hall: off (default), mild or full (the bare option), as tafel run --realism")
    match.add_argument("--record-dir", type=Path, metavar="DIR", help="every robot records its log here (TEAM_PLAYER.mcap)")
    match.add_argument("--record-reps", metavar="A,B", help="record only these representations (as tafel run --record-reps)")
    match.add_argument("--result", type=Path, metavar="FILE.json", help="also write the result's JSON object here")
    match.add_argument("--resolution", default="320x240",  # the platforms' DEFAULT_RESOLUTION
                       help="camera image size WIDTHxHEIGHT for both cameras, or TOP,BOTTOM (the NAO's: 640x480,320x240)")
    match.add_argument("--ready-seconds", type=positive(float), default=30.0, help="longest READY (default 30)")
    match.add_argument("--goals", type=positive(int), metavar="N", help="end the game when a team has scored N goals (drills, tests)")
    match.add_argument("--halves", type=int, choices=[1, 2], default=2, help="play both halves (default) or only the first (drills, tests)")
    match.add_argument("--shoot-out", dest="shoot_out", nargs="?", choices=["never", "tie", "always", "only"], const="only",
                       default="never", help="a penalty shoot-out as GameController3 runs it: only (--shoot-out alone) plays just the "
                                             "shoot-out; tie after the halves when the score is level; always after the halves")
    match.add_argument("--penalty-shots", type=positive(int), default=3, metavar="N", help="penalty shots per team (the rules: 3)")
    match.add_argument("--sudden-death-shots", type=int, default=3, metavar="N",
                       help="at most N more shots per team in sudden death while the shoot-out is level (the rules: 3)")
    match.add_argument("--call", dest="calls", action="append", default=[], type=parse_call, metavar="S:SET_PLAY:TEAM",
                       help="the referee calls a free kick for team 1 or 2 at S s of the match, once PLAYING, the ball placed as "
                            f"the set play places it ({', '.join(CALLABLE_SET_PLAYS)}; repeatable; drills, tests)")
    add_module_path_argument(match)
    match.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                       help="a configuration override for every robot's program (repeatable)")
    for team in (1, 2):
        match.add_argument(f"--team{team}-set", dest=f"team{team}_overrides", action="append", default=[], metavar="KEY=VALUE",
                           help=f"a configuration override for team {team}'s robots only, after --set (repeatable)")


def add_scenario_commands(commands: Any) -> None:
    from tafel.tools.simulation.batch import default_workers

    scenarios = commands.add_parser("scenarios", help="run scenario files many times with perturbations; success rates",
                                    description="Scenario tests: each file N times with seeded perturbations, headless at full "
                                                "speed, on all cores or on Ray. Exit status 1 when a success rate is below its "
                                                "scenario's requirement, 2 for a bad file or option.")
    actions = scenarios.add_subparsers(dest="scenarios_command", metavar="ACTION")
    actions.required = True
    run = actions.add_parser("run", help="run scenarios and report success rates")
    run.add_argument("files", nargs="+", type=Path, metavar="FILE.toml")
    run.add_argument("--repeat", type=int, default=10, metavar="N", help="runs of every scenario (default 10)")
    run.add_argument("--seed", type=int, default=0, metavar="S", help="base seed: the same seed gives the same runs (default 0)")
    run.add_argument("--workers", type=int, metavar="K", help=f"runs at a time (default: all cores, here {default_workers()})")
    run.add_argument("--out", type=Path, default=Path("scenario-runs.csv"), metavar="FILE",
                     help="one row per run: .csv or .jsonl (default: %(default)s)")
    run.add_argument("--artifacts", type=Path, metavar="DIR",
                     help="where logs of failed runs go; on a Ray cluster a folder every node shares (default: scenario-logs)")
    run.add_argument("--no-logs", action="store_true", help="do not record failed runs again")
    run.add_argument("--ray", nargs="?", const="local", metavar="ADDRESS",
                     help="run each run as a Ray task: alone, on a local Ray instance; with HOST:PORT, on that cluster")
    add_module_arguments(run)
    actions.add_parser("predicates", help="the predicates success conditions are built from, with their parameters")


def add_replay_batch_command(commands: Any) -> None:
    from tafel.tools.simulation.batch import default_workers

    batch = commands.add_parser("replay-batch", help="replay many logs with a changed configuration or module; what differs",
                                description="Replay every log (paths or globs) with the changes given, record the replay, and "
                                            "report per log what differs from the recorded outputs (--compare) and chosen "
                                            "metrics, as CSV and a summary. Exit status 1 when --compare finds a difference, "
                                            "2 for a log that cannot be replayed or a bad option.")
    batch.add_argument("logs", nargs="+", metavar="LOG_OR_GLOB")
    batch.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                       help="configuration override for every replay (repeatable), as with tafel run")
    batch.add_argument("--replace", default="", metavar="A,B", help="feed these recorded representations instead of running their providers")
    batch.add_argument("--compare", action="store_true", help="compare every replay with its log, as tafel log compare does")
    batch.add_argument("--metric", action="append", default=[], metavar="REP.FIELD",
                       help="report the mean of a representation's field, recorded and replayed (repeatable); tafel log info lists them")
    batch.add_argument("--out", type=Path, default=Path("replay-batch.csv"), metavar="FILE.csv", help="one row per log (default: %(default)s)")
    batch.add_argument("--artifacts", type=Path, metavar="DIR", help="keep the replayed logs in this folder (on Ray: one every node shares)")
    batch.add_argument("--workers", type=int, metavar="K", help=f"logs at a time (default: all cores, here {default_workers()})")
    batch.add_argument("--ray", nargs="?", const="local", metavar="ADDRESS",
                       help="replay each log as a Ray task: alone, on a local Ray instance; with HOST:PORT, on that cluster")
    add_module_arguments(batch)


def add_log_commands(commands: Any) -> None:
    log = commands.add_parser("log", help="inspect and export recorded logs")
    actions = log.add_subparsers(dest="log_command", metavar="ACTION")
    actions.required = True
    info = actions.add_parser("info", help="duration, frames per context, channels with counts and sizes")
    info.add_argument("file", type=Path)
    info.add_argument("--json", action="store_true", help="print the information as JSON")
    export = actions.add_parser("export", help="representations as CSV or JSON lines, images as PNG files")
    export.add_argument("file", type=Path)
    export.add_argument("--rep", required=True, help="representation name (tafel log info lists them)")
    export.add_argument("--context", type=context_name, metavar="CONTEXT", help="only this context's channel (cognition or motion)")
    export.add_argument("--format", required=True, choices=["csv", "jsonl", "png"])
    export.add_argument("--out", required=True, type=Path, help="output file (csv, jsonl) or folder (png)")
    compare = actions.add_parser("compare", help="where two logs differ: per channel, the first differing frame and field",
                                 description="Compare two logs frame by frame, per context and representation; "
                                             "exit status 1 when they differ.")
    compare.add_argument("first", type=Path, metavar="A.mcap")
    compare.add_argument("second", type=Path, metavar="B.mcap")
    compare.add_argument("--rep", metavar="A,B", help="only these representations")
    compare.add_argument("--json", action="store_true", help="print the report as JSON")
    compare.add_argument("--all", action="store_true", dest="timing",
                         help="also compare what is not state: timing (ModuleTimes) and debug output (drawings, plots)")
    piece = actions.add_parser("slice", help="copy a piece of a log (some representations, some seconds) into a new one",
                               description="A situation from a game as a small log: for module tests (replay_module) "
                                           "and for sharing.")
    piece.add_argument("file", type=Path)
    piece.add_argument("--out", required=True, type=Path, help="the new log")
    piece.add_argument("--rep", metavar="A,B", help="only these representations (default: all)")
    piece.add_argument("--start", type=float, default=0.0, metavar="S", help="seconds after the log's start (default 0)")
    piece.add_argument("--seconds", type=float, metavar="N", help="how long (default: to the end)")
    convert = actions.add_parser("convert", help="a copy of a log with Foxglove's channels added (images, scene, series)",
                                 description="For logs recorded before recordings carried Foxglove's channels: the copy "
                                             "opens in Foxglove and Lichtblick with images, 3D scene and plots.")
    convert.add_argument("file", type=Path)
    convert.add_argument("--out", required=True, type=Path, help="the new log")
    convert.add_argument("--jpeg-quality", type=int, default=80, metavar="Q", help="JPEG quality of the images, 1 to 100 (default 80)")


def add_console_command(commands: Any) -> None:
    console = commands.add_parser("console", help="talk to a running program's debug server")
    console.add_argument("--host", default="127.0.0.1")
    console.add_argument("--port", type=port_number, default=5401)
    console.add_argument("--token", help="send 'auth TOKEN' first")
    console.add_argument("-c", dest="one_command", metavar="COMMAND", help="run one command, print its answer and exit (status 1 on error:)")


def team_number(text: str) -> int:
    """A GameController team number: 1 to 254."""
    from tafel.core.framework.values import convert

    return convert(text, int, where="", bounds=(1, 254), text=True, expected="a team number from 1 to 254 (the GameController's)",
                   error=argparse.ArgumentTypeError)


def add_team_command(commands: Any) -> None:
    """``tafel team``: the code is in ``tafel.tools.viewers.team``."""
    team = commands.add_parser("team", help="TeamControl in the browser: every robot of a team, from its messages on the network",
                               description="Listens (receive only, within the rules) to a team's messages on UDP 10000 + team "
                                           "number and to the GameController, and serves the web view's Team panel: every robot "
                                           "heard with its pose, role, intention, ball, fallen or penalized, the time since its "
                                           "last message, and the game state. No program needs to run.")
    team.add_argument("--team", type=team_number, required=True, metavar="N", help="the team number (1 to 254)")
    team.add_argument("--port", type=port_number, default=0, metavar="P",
                      help="UDP port of the team's messages (default 10000 + N; tafel match prints its own)")
    team.add_argument("--game-controller-port", type=port_number, default=3838, metavar="P",
                      help="UDP port of the GameController's packets (default %(default)s)")
    team.add_argument("--host", default="127.0.0.1", help="address the page is served on (default %(default)s)")
    team.add_argument("--web-port", type=port_number, default=5480, metavar="P", help="the page's port (default %(default)s; 0: a free one)")
    team.add_argument("--debug-port", type=port_number, default=0, metavar="P",
                      help="the debug server's port, for the console's team:robots (default: a free one)")
    team.add_argument("--debug-token", metavar="TOKEN", help="the page and the console must give this token")
    team.add_argument("--seconds", type=positive(float), metavar="S", help="stop after S seconds (default: at Ctrl-C)")


def add_deploy_commands(commands: Any) -> None:
    """``tafel robots`` and ``tafel deploy``: the code is in ``tafel.tools.robot.deploy``."""
    robots = commands.add_parser("robots", help="list the robots of robots.toml, whether they answer and which release they run")
    deploy = commands.add_parser("deploy", help="build, copy and install the program on a robot and (re)start it there",
                                 description="Builds the wheel, its dependencies for the robot and the configuration, copies "
                                             "what changed over SSH (rsync), installs it as a new release and starts it; a "
                                             "release that fails to install or start leaves the robot on the one it had.")
    deploy.add_argument("robot", metavar="ROBOT", help="a robot's name in robots.toml")
    deploy.add_argument("--dry-run", action="store_true", help="say what would be copied and installed; change nothing")
    deploy.add_argument("--staging", type=Path, metavar="DIR", help="where the release is built (default ~/.cache/tafel/deploy/ROBOT)")
    for parser in (robots, deploy):
        parser.add_argument("--config", type=Path, metavar="DIR", help="a configuration folder with robots.toml (on top of the shipped one)")
        parser.add_argument("--ssh-config", type=Path, metavar="FILE", help="an SSH configuration file (default: your own)")


def add_program_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--platform", help="where to run (see 'tafel platforms'); default from configuration")
    parser.add_argument("--config", type=Path, metavar="DIR",
                        help="a configuration folder whose layers go on top of the shipped defaults; "
                             "parameter:store and modules:store write into DIR/private/private.toml")
    parser.add_argument("--robot", help="robot layer config/robot/NAME.toml")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                        help="override a configuration value, e.g. runtime.cognition_hz=15 (repeatable)")
    parser.add_argument("--strict", action="store_true",
                        help="modules the platform cannot feed are an error instead of being pruned")
    add_module_arguments(parser)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="tafel", description="Run and inspect Tafel robot control programs.")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")
    commands.required = True

    run = commands.add_parser("run", help="run the program on a platform",
                              epilog="Each platform has options of its own: tafel platforms --verbose lists them.")
    add_program_arguments(run)
    limit = run.add_mutually_exclusive_group()
    limit.add_argument("--seconds", type=positive(float), help="stop after this much platform time")
    limit.add_argument("--frames", type=positive(int), help="stop after N frames of the main context (motion, else cognition)")
    run.add_argument("--speed", type=parse_speed, default=1.0, help="pace against the wall clock: a factor, or 'max'")
    run.add_argument("--concurrent", action="store_true", help="run the contexts in parallel processes")
    run.add_argument("--status-interval", type=positive(float), default=2.0, metavar="S",
                     help="seconds between status lines (default: %(default)s)")
    run.add_argument("-v", "--verbose", action="store_true", help="log informational messages")
    run.add_argument("--ready-file", type=Path, metavar="FILE",
                     help="write FILE (the program's pid) once every context has run a frame, so that whoever started "
                          "the program knows it runs (tafel deploy waits for it); under systemd READY=1 goes to $NOTIFY_SOCKET")
    run.add_argument("--record", type=Path, metavar="FILE.mcap", help="record representations into an MCAP log")
    run.add_argument("--record-dir", type=Path, default=Path("logs"), metavar="DIR",
                     help="the only folder debug clients may record into with log:start (default: %(default)s)")
    run.add_argument("--record-reps", metavar="A,B",
                     help="what to record besides the sensor data (default: [recording] representations; 'all': everything; "
                          "motion/NAME: that context's only)")
    run.add_argument("--debug-port", type=port_number, default=None, metavar="P", help=f"debug server port (default {DEFAULT_DEBUG_PORT}; 0 takes a free one)")
    run.add_argument("--debug-host", default="127.0.0.1", metavar="H", help="debug server address (default: %(default)s)")
    token = run.add_mutually_exclusive_group()
    token.add_argument("--debug-token", metavar="T", help="clients must send 'auth T' first")
    token.add_argument("--debug-token-file", type=Path, metavar="F",
                       help="read the token from a file (it then does not show in ps); a trailing newline is dropped")
    run.add_argument("--debug-max-connections", type=positive(int), default=32, metavar="N",
                     help="debug connections served at once; more get an error line (default: %(default)s)")
    run.add_argument("--debug-idle-timeout", type=positive(float), default=30.0, metavar="S",
                     help="close a debug connection that has not authenticated (without a token: sent no command) "
                          "within S seconds (default: %(default)s)")
    run.add_argument("--no-debug", action="store_true", help="run without the debug server (and without the web view)")
    run.add_argument("--web-port", type=port_number, default=DEFAULT_WEB_PORT, metavar="P",
                     help="serve RobotControl in the browser on the debug server's address at this port "
                          "(default %(default)s; 0 takes a free one)")
    run.add_argument("--no-web", action="store_true", help="run without the web view")
    run.add_argument("--watch", action="store_true",
                     help="reload a module into the running program when its source file changes (keeps the blackboard)")
    run.add_argument("--foxglove", nargs="?", const=f"127.0.0.1:{DEFAULT_FOXGLOVE_PORT}", metavar="[HOST:]PORT",
                     help=f"serve Foxglove and Lichtblick live over WebSocket (default 127.0.0.1:{DEFAULT_FOXGLOVE_PORT}; "
                          "with --debug-token clients must give it: ws://HOST:PORT/?token=T)")

    # the tools' command lines only: each tool's code (MuJoCo for match, protobuf for logs) loads when it runs
    add_log_commands(commands)
    add_console_command(commands)
    add_match_command(commands)
    add_team_command(commands)
    add_scenario_commands(commands)
    add_replay_batch_command(commands)
    add_deploy_commands(commands)

    platforms = commands.add_parser("platforms", help="list the platforms and what they provide and consume")
    platforms.add_argument("--verbose", "-v", action="store_true", help="also list each platform's options")

    view = commands.add_parser("view", help="RobotControl in the browser for a recorded log: play, pause, step and scrub",
                               epilog="The recorded representations are shown as recorded; modules whose outputs the log "
                                      "does not hold run again on the recorded data.")
    view.add_argument("file", type=Path, metavar="FILE.mcap")
    view.add_argument("--web-port", type=port_number, default=DEFAULT_WEB_PORT, metavar="P",
                      help="serve the page at this port (default %(default)s; 0 takes a free one)")
    view.add_argument("--debug-port", type=port_number, default=0, metavar="P", help="debug server port (default: a free one)")
    view.add_argument("--debug-host", default="127.0.0.1", metavar="H", help="the address of both (default: %(default)s)")
    view.add_argument("--debug-token", metavar="T", help="clients and the page must send 'auth T' first")
    view.add_argument("--speed", type=parse_speed, default=1.0, help="playing speed: a factor, or 'max'")
    add_module_path_argument(view)

    modules = commands.add_parser("modules", help="show the module graph of both contexts")
    add_program_arguments(modules)
    modules.add_argument("--dot", action="store_true", help="print Graphviz DOT of both contexts and their hand-overs")
    return parser


