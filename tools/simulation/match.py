"""``tafel match``: a simulated game. One MuJoCo world, one program per robot in a process of its own,
the simulated GameController (``referee.py``), all in lockstep.

Every motion tick (10 ms) the world waits for the joint commands of every robot, steps the physics,
lets the referee judge and send its packet, and hands every robot its sensors of the new tick. The
robots' programs are ``tafel run --platform match``: each has its own contexts, blackboards, debug
server (its port is listed at the start) and, with ``--record-dir``, its own log. A match with a
seed is deterministic; it uses every core, as the programs run in parallel between the world's ticks.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import secrets
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass
from multiprocessing.connection import Connection, Listener, wait
from pathlib import Path
from typing import Any, TextIO

from tafel.platforms.field_world import level_look
from tafel.platforms.match_robot import AUTHKEY_ENV
from tafel.platforms.match_world import TICK_NS, MatchWorld, Side
from tafel.platforms.mujoco_sim import offscreen_size
from tafel.platforms.realism import parse_realism, realism_level
from tafel.platforms.simulated import parse_resolutions
from tafel.representations.game import GamePhase, SetPlay, State
from tafel.tools.simulation.officiating import Player
from tafel.tools.simulation.passes import PassCounter
from tafel.tools.simulation.referee import Referee
from tafel.tools.simulation.rules import MAX_PLAYERS_PER_TEAM
from tafel.tools.simulation.set_plays import Call

TEAM_NUMBERS = (1, 2)
#: where robots enter (team frame, mm and rad): on the own half's touchline, facing the field
ENTRY = [(-3600.0 + 700.0 * k, -3000.0, math.pi / 2) for k in range(MAX_PLAYERS_PER_TEAM)]
CONNECT_TIMEOUT_S = 120.0  # robots import, plan and open their cameras before they join
STOP_TIMEOUT_S = 20.0


@dataclass
class Robot:
    """One robot's program: its process, where its debug server is, what it printed."""

    player: Player
    process: subprocess.Popen
    debug: str = ""
    log: Path | None = None
    connection: Connection | None = None
    errors: list[str] | None = None
    cameras: bool = False
    """whether it renders its cameras (then it gets the world's positions every tick)"""


def cpu_seconds(pid: int | None = None) -> float | None:
    """CPU seconds (user and system) a process has used so far: this one, or a child by ``pid`` (Linux
    ``/proc``; None where it cannot be read). What the match's limit on this machine is computed from."""
    if pid is None:
        return time.process_time()
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError):
        return None


def free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def drain(stream: TextIO, sink: list[str] | None) -> None:
    for line in stream:
        if sink is not None:
            sink.append(line)
            del sink[:-40]  # the last lines are what an error needs


class Match:
    def __init__(self, args: argparse.Namespace) -> None:
        self.args = args
        sizes = args.teams
        self.players = [Player(team=t, number=n + 1, index=0, side=Side(1.0 if t == 0 else -1.0)) for t in (0, 1) for n in range(sizes[t])]
        for index, player in enumerate(self.players):
            player.index = index
        places = [player.side.to_world(*ENTRY[player.number - 1]) for player in self.players]
        sizes = parse_resolutions(args.resolution)
        #: --realism: every robot's camera pipeline (seeded by its own seed) and the world's hall (seeded by --seed)
        self.realism = parse_realism(getattr(args, "realism", "off"))
        level = realism_level(self.realism)
        look = level_look(args.seed, level)
        self.world = MatchWorld([(x, y) for x, y, _ in places], offscreen=offscreen_size(sizes), look=look,
                                shadows=bool(level and level.shadows))
        for player, (x, y, heading) in zip(self.players, places):
            self.world.move_robot(player.index, x, y, heading)
        self.ports = {"game_controller_port": free_udp_port(), "return_port": free_udp_port()}
        self.team_ports = (free_udp_port(), free_udp_port())
        self.referee = Referee(self.world, TEAM_NUMBERS, self.players, args.seconds / args.halves, self.ports["game_controller_port"],
                               self.ports["return_port"], self.team_ports, ready_s=args.ready_seconds,
                               goals_to_end=args.goals, halves=args.halves, shoot_out=args.shoot_out, penalty_shots=args.penalty_shots,
                               sudden_death_shots=max(0, args.sudden_death_shots), seed=int(args.seed),
                               calls=[Call(seconds, SetPlay[name], team) for seconds, name, team in args.calls])
        self.key = secrets.token_hex(16)
        self.listener = Listener(("127.0.0.1", 0), backlog=2 * MAX_PLAYERS_PER_TEAM, authkey=self.key.encode())  # all join at once
        self.robots: list[Robot] = []
        #: completed passes and own goals, from ground truth (``passes.py``)
        self.passes = PassCounter([player.team for player in self.players])
        #: CPU seconds of the world's process and of each robot's at the kickoff and at the final whistle
        self.cpu_at: dict[str, list[float | None]] = {}

    def take_cpu(self, when: str) -> None:
        """Note the CPU seconds every process of the match has used by now (``kickoff`` or ``whistle``)."""
        self.cpu_at[when] = [cpu_seconds(), *(cpu_seconds(robot.process.pid) for robot in self.robots)]

    def cpu_figures(self) -> dict[str, Any]:
        """CPU seconds per simulated second of play: the world's, each robot's mean, and the real-time factor
        this machine's cores allow at best (cores / all processes' CPU per simulated second)."""
        start, end, simulated = self.cpu_at.get("kickoff"), self.cpu_at.get("whistle"), self.world.time_ns * 1e-9
        if not (start and end and simulated > 0) or any(v is None for v in (*start, *end)):
            return {}
        used = [b - a for a, b in zip(start, end)]  # type: ignore[operator]
        robots = used[1:]
        per_robot = sum(robots) / len(robots) / simulated if robots else 0.0
        total = sum(used) / simulated
        return {"cpu_s_per_sim_s_world": round(used[0] / simulated, 3), "cpu_s_per_sim_s_per_robot": round(per_robot, 3),
                "cpu_count": os.cpu_count(), "limit_realtime_factor": round((os.cpu_count() or 1) / total, 3) if total > 0 else None}

    # ---------------------------------------------------------------------------------- robots
    def robot_seed(self, player: Player) -> int:
        """A robot's ``--seed`` (its sensor noise and camera pipeline): the match's plus its index, so each differs."""
        return int(self.args.seed) + player.index

    def robot_command(self, player: Player) -> list[str]:
        """The command line of a robot's program (``tafel run --platform match``)."""
        host, port = self.listener.address
        team = TEAM_NUMBERS[player.team]
        settings = {**self.ports, "team_port": self.team_ports[player.team], "team_number": team, "player_number": player.number,
                    "broadcast": "127.255.255.255"}
        return [sys.executable, "-m", "tafel.tools.cli", "run", "--platform", "match", "--world", f"{host}:{port}",
                "--index", str(player.index), f"--side={'+x' if player.side.sign > 0 else '-x'}", "--cameras", self.args.cameras,
                "--resolution", self.args.resolution, "--seed", str(self.robot_seed(player)), f"--realism={self.realism}", "--speed", "max",
                "--debug-port", "0", "--no-web", "--status-interval", "3600",
                "--set", "parameters.GameStateProvider.start_state=initial",
                # the team message budget is paced over the game's halves, here shorter than the SPL's
                "--set", f"parameters.TeamMessageSender.half_s={min(3600.0, max(1.0, self.args.seconds / self.args.halves)):g}",
                *(a for key, value in settings.items() for a in ("--set", f"game.{key}={json.dumps(value)}")),
                *(a for folder in self.args.module_path for a in ("--module-path", str(folder))),
                *(a for override in self.args.overrides for a in ("--set", override)),
                *(a for override in getattr(self.args, f"team{player.team + 1}_overrides") for a in ("--set", override))]

    def start_robots(self) -> None:
        for player in self.players:
            team = TEAM_NUMBERS[player.team]
            command = self.robot_command(player)
            log = None
            if self.args.record_dir is not None:
                self.args.record_dir.mkdir(parents=True, exist_ok=True)
                log = self.args.record_dir / f"team{team}_player{player.number}.mcap"
                command += ["--record", str(log), *(["--record-reps", self.args.record_reps] if self.args.record_reps else [])]
            process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                       env={**os.environ, AUTHKEY_ENV: self.key})
            self.robots.append(Robot(player, process, log=log, errors=[]))
        for robot in self.robots:
            first = robot.process.stdout.readline()
            found = re.match(r"debug server listening on (\S+)", first)
            if not found:
                raise RuntimeError(f"robot {self.name(robot)} did not start: {first}{robot.process.stderr.read()[-3000:]}")
            robot.debug = found[1]
            threading.Thread(target=drain, args=(robot.process.stdout, None), daemon=True).start()
            threading.Thread(target=drain, args=(robot.process.stderr, robot.errors), daemon=True).start()

    def connect(self) -> None:
        """Accept every robot's connection and give it the world's model (to render its cameras from)."""
        by_index = {robot.player.index: robot for robot in self.robots}
        self.listener._listener._socket.settimeout(CONNECT_TIMEOUT_S)  # noqa: SLF001 - Listener has no timeout of its own
        for _ in self.robots:
            try:
                connection = self.listener.accept()
            except (TimeoutError, socket.timeout):
                late = [self.name(r) for r in self.robots if r.connection is None]
                raise RuntimeError(f"robots {', '.join(late)} did not join within {CONNECT_TIMEOUT_S:g} s") from None
            _, index, cameras = connection.recv()
            by_index[index].connection = connection
            connection.send(("model", self.world.xml, self.world.ball_color, len(self.robots), self.world.look))
            by_index[index].cameras = cameras

    @staticmethod
    def name(robot: Robot) -> str:
        return f"team {TEAM_NUMBERS[robot.player.team]} player {robot.player.number}"

    # ------------------------------------------------------------------------------------- play
    def play(self) -> str:
        """Tick until the game is over; the reason it ended."""
        speed = self.args.speed
        started, time_ns, last_score, fouls_told, shots_told = time.monotonic(), 0, self.referee.score(), 0, 0
        connections = {robot.connection: robot for robot in self.robots}
        while True:
            waiting, commands = set(connections), {}
            while waiting:
                for connection in wait(list(waiting), timeout=60.0) or []:
                    robot = connections[connection]
                    try:
                        kind, robot_time, targets, stiffness = connection.recv()
                    except (EOFError, OSError):
                        return f"the program of {self.name(robot)} ended: {''.join(robot.errors or [])[-2000:]}"
                    commands[robot.player.index] = (robot_time, targets, stiffness)
                    waiting.discard(connection)
                if waiting and all(r.process.poll() is not None for r in (connections[c] for c in waiting)):
                    return "robot programs ended"
            for index, (_, targets, stiffness) in commands.items():
                self.world.drive(index, targets, stiffness)
            previous = self.world.time_ns
            self.world.step_to(time_ns)
            self.watch_passes(time_ns * 1e-9)
            events = len(self.referee.events)
            self.referee.tick(time_ns * 1e-9, (time_ns - previous) * 1e-9)
            for event in self.referee.events[events:]:  # a goal: whose last touch it was
                conceding = 1 - TEAM_NUMBERS.index(int(event.what.split()[1])) if event.what.startswith("GOAL ") else None
                toucher = self.passes.last_toucher
                if conceding is not None and toucher is not None:
                    own = self.passes.goal(conceding)
                    player = self.players[toucher]
                    print(f"[match] t={event.time_s:.1f}s last touch: team {TEAM_NUMBERS[player.team]} player {player.number}"
                          + (f": own goal of team {TEAM_NUMBERS[conceding]}" if own else ""), flush=True)
            if self.referee.score() != last_score:
                last_score = self.referee.score()
                print(f"[match] t={time_ns * 1e-9:.1f}s goal: {TEAM_NUMBERS[0]}:{TEAM_NUMBERS[1]} {last_score}", flush=True)
            for foul in self.referee.fouls[fouls_told:]:
                who = f"team {foul.team} player {foul.player}" if foul.player else f"team {foul.team}"
                print(f"[match] t={foul.time_s:.1f}s foul: {who} {foul.penalty.name if foul.player else ''} ({foul.reason})", flush=True)
            fouls_told = len(self.referee.fouls)
            for number, shot in enumerate(self.referee.shots[shots_told:], start=shots_told + 1):
                print(f"[match] t={shot.time_s:.1f}s penalty shot {number}{' (sudden death)' if shot.sudden_death else ''}: team "
                      f"{shot.team} player {shot.striker} against keeper {shot.keeper or 'none'}: {shot.outcome} "
                      f"(shoot-out {self.referee.shoot_out_score()})", flush=True)
            shots_told = len(self.referee.shots)
            if self.referee.over:
                return "the game is over"
            for robot in self.robots:
                robot.connection.send(("sensors", self.world.snapshot(robot.player.index, robot.cameras)))
            time_ns += TICK_NS
            if speed:
                delay = started + time_ns * 1e-9 / speed - time.monotonic()
                if delay > 0:
                    time.sleep(delay)

    def watch_passes(self, now: float) -> None:
        """Show the pass counter this tick's ground truth (before the referee judges it: a goal's last touch
        is still known), and print a completed pass."""
        game = self.referee.game
        playing = game.state is State.playing and game.game_phase is GamePhase.normal
        on_field = {player.index for player in self.referee.on_field()}
        robots = [self.world.robot_pose(p.index)[:2] if p.index in on_field else None for p in self.players]
        done = self.passes.observe(now, self.world.ball_position(), robots, playing)
        if done is not None:
            kicker, receiver = self.players[done.kicker], self.players[done.receiver]
            print(f"[match] t={now:.1f}s pass: team {TEAM_NUMBERS[done.team]} player {kicker.number} to player {receiver.number}, "
                  f"{done.distance_mm / 1000.0:.1f} m", flush=True)

    def finish(self, reason: str) -> dict[str, Any]:
        for robot in self.robots:
            if robot.connection is not None:
                try:
                    robot.connection.send(("end", "the match is over"))
                except OSError:
                    pass
        deadline = time.monotonic() + STOP_TIMEOUT_S
        for robot in self.robots:
            try:
                robot.process.wait(timeout=max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                robot.process.kill()
                robot.process.wait()
        self.referee.close()
        self.listener.close()
        referee = self.referee
        sent = sum(referee.messages)
        return {
            "teams": [{"team": TEAM_NUMBERS[t], "robots": self.args.teams[t], "score": referee.game.teams[t].score - referee.shoot_out_goals[t],
                       "team_messages": referee.messages[t], "team_messages_heard": referee.messages_heard[t],
                       "message_budget_left": referee.game.teams[t].message_budget,
                       "fouls": sum(f.team == TEAM_NUMBERS[t] for f in referee.fouls),
                       "passes": self.passes.count(t), "own_goals": self.passes.own_goals[t],
                       "illegal_communication": referee.illegal_communication[t]} for t in (0, 1)],
            "fouls": [{"time_s": round(f.time_s, 2), "team": f.team, "player": f.player, "penalty": f.penalty.name, "reason": f.reason}
                      for f in referee.fouls],
            "score": referee.score(),
            "passes": [{"time_s": round(p.time_s, 2), "team": TEAM_NUMBERS[p.team], "kicker": self.players[p.kicker].number,
                        "receiver": self.players[p.receiver].number, "distance_mm": round(p.distance_mm)} for p in self.passes.passes],
            **({"shoot_out": {"score": referee.shoot_out_score(), "winner": referee.winner,
                              "shots": [{"time_s": round(s.time_s, 2), "team": s.team, "striker": s.striker, "keeper": s.keeper,
                                         "outcome": s.outcome, "sudden_death": s.sudden_death} for s in referee.shots]}}
               if referee.game.game_phase is GamePhase.penalty_shoot else {}),
            "set_plays": [{"start_s": round(r.start_s, 2), "end_s": round(r.end_s, 2), "set_play": r.set_play, "kicking_team": r.kicking_team,
                           "ended": r.ended, "nearest_mm": round(r.nearest_mm) if math.isfinite(r.nearest_mm) else None,
                           "nearest_player": r.nearest_player,
                           "nearest_at_start_mm": round(r.nearest_at_start_mm) if math.isfinite(r.nearest_at_start_mm) else None}
                          for r in referee.restrictions],
            "ended": reason,
            "realism": self.realism,
            "simulated_s": round(self.world.time_ns * 1e-9, 2),
            "events": [{"time_s": round(e.time_s, 2), "event": e.what} for e in referee.events],
            "bytes_per_team_message": round(referee.message_bytes / sent, 1) if sent else 0,
            **self.cpu_figures(),
            "robots": [{"team": TEAM_NUMBERS[r.player.team], "player": r.player.number, "debug": r.debug, "returns": r.player.returns,
                        "seed": self.robot_seed(r.player), "exit_status": r.process.returncode, **({"log": str(r.log)} if r.log else {})} for r in self.robots],
        }


def command_match(args: argparse.Namespace, extra: Sequence[str]) -> int:
    """Run a match; print its events as they come and its result as one JSON object at the end."""
    if extra:
        print(f"tafel match: error: unrecognized arguments: {' '.join(extra)}", file=sys.stderr)
        return 2
    match = Match(args)
    started = kickoff = final_whistle = time.monotonic()
    reason = "interrupted"
    try:
        match.start_robots()
        match.connect()
        for robot in match.robots:
            print(f"[match] team {TEAM_NUMBERS[robot.player.team]} player {robot.player.number}: debug server {robot.debug}"
                  + (f", log {robot.log}" if robot.log else ""), flush=True)
        if match.realism != "off":
            print(f"[match] realism {match.realism}: every robot's camera pipeline seeded by its own seed "
                  f"({', '.join(str(match.robot_seed(r.player)) for r in match.robots)}), one hall from --seed {args.seed}"
                  + ("" if args.cameras == "on" else " (no effect: --cameras off)"), flush=True)
        for side, team in enumerate(TEAM_NUMBERS):  # what `tafel team` listens to, to watch a team of this match
            print(f"[match] team {team} talks on UDP {match.team_ports[side]}, the GameController on "
                  f"{match.ports['game_controller_port']}: tafel team --team {team} --port {match.team_ports[side]} "
                  f"--game-controller-port {match.ports['game_controller_port']}", flush=True)
        kickoff = time.monotonic()
        match.take_cpu("kickoff")
        reason = match.play()
        final_whistle = time.monotonic()
        match.take_cpu("whistle")
    except KeyboardInterrupt:
        reason = "interrupted"
    except RuntimeError as exc:
        reason = str(exc)
    finally:
        result = match.finish(reason)
    result["wall_s"] = round(time.monotonic() - started, 2)
    result["startup_s"] = round(kickoff - started, 2)
    result["realtime_factor"] = round(result["simulated_s"] / max(1e-9, final_whistle - kickoff), 3)  # start-up and shutdown apart
    line = json.dumps(result)
    if args.result is not None:
        args.result.write_text(line + "\n")
    fouls = ":".join(str(team["fouls"]) for team in result["teams"])
    passes = ":".join(str(team["passes"]) for team in result["teams"])
    shoot_out = result.get("shoot_out")
    decided = "" if shoot_out is None else (f", shoot-out {shoot_out['score']} ("
                                            + (f"team {shoot_out['winner']} wins)" if shoot_out["winner"] else "undecided: a coin toss)"))
    realism = "" if match.realism == "off" else f", realism {match.realism}"
    print(f"[match] {reason}; score {result['score']} (team {TEAM_NUMBERS[0]} : team {TEAM_NUMBERS[1]}){decided}, fouls {fouls}, passes {passes}{realism}", flush=True)
    print(line, flush=True)
    return 0 if reason == "the game is over" else 1
