"""The Team view (TeamControl): ``tafel team`` listens to a team's messages and the GameController on the
network, receive only, and the web view draws every robot heard where its messages put it.

The robots here are real UDP team messages (``pack_message``) sent from the test to ``tafel team`` on
free ports, as a match's robots send them; the GameController is a real ``RoboCupGameControlData``.
"""

from __future__ import annotations

import json
import re
import socket
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from tafel.modules.communication.game_controller_codec import encode_game_state
from tafel.modules.communication.team_message_codec import pack_message
from tafel.representations.game import GameState, Penalty, RobotInfo, State, TeamInfo
from tafel.representations.team import Intention, Role, TeamMessage
from tafel.tools.simulation.match import free_udp_port
from tafel.tools.viewers.team import FORGET_AFTER_S, TeamListener
from tests.support.browser import WebProgram, launch, missing_browser, open_page, wait_for
from tests.test_web_view import screenshot_dir

TEAM = 7
ROBOTS = (  # two robots of a team: a goalkeeper in its goal, a fallen striker going for the ball
    TeamMessage(team=TEAM, player=1, pose_valid=True, x=-4100.0, y=150.0, rotation=0.0, role=Role.goalkeeper,
                intention=Intention.keep_goal, ball_seen=True, ball_x=1800.0, ball_y=-1200.0, ball_age=0.4),
    TeamMessage(team=TEAM, player=2, pose_valid=True, fallen=True, x=1200.0, y=-1600.0, rotation=2.0, role=Role.striker,
                intention=Intention.play_ball, ball_seen=True, ball_x=1800.0, ball_y=-1200.0, ball_age=0.1, time_to_ball=3.5),
)
COLOURS = {"goalkeeper": (0x7C, 0x3A, 0xED), "striker": (0xDC, 0x26, 0x26)}  # team.js's role colours


def game_packet() -> bytes:
    players = [RobotInfo() for _ in range(20)]
    players[1] = RobotInfo(Penalty.player_pushing, 25)
    return encode_game_state(GameState(state=State.playing, secs_remaining=431, players_per_team=2, teams=[
        TeamInfo(team_number=TEAM, score=2, message_budget=1130, players=players), TeamInfo(team_number=8, score=1)]))


class Sender:
    """What the robots and the GameController send, five times a second, in a thread of its own."""

    def __init__(self, team_port: int, game_controller_port: int) -> None:
        self.socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.ports = (team_port, game_controller_port)
        self.stopping = threading.Event()
        self.thread = threading.Thread(target=self._send, daemon=True)
        self.thread.start()

    def _send(self) -> None:
        while not self.stopping.wait(0.2):
            for robot in ROBOTS:
                self.socket.sendto(pack_message(robot), ("127.0.0.1", self.ports[0]))
            self.socket.sendto(b"not a team message", ("127.0.0.1", self.ports[0]))
            self.socket.sendto(game_packet(), ("127.0.0.1", self.ports[1]))

    def stop(self) -> None:
        self.stopping.set()
        self.thread.join(timeout=5)
        self.socket.close()


def test_the_listener_keeps_what_each_robot_said_last_and_counts_what_is_not_its_teams() -> None:
    listener = TeamListener(TEAM)
    listener.take_message(pack_message(ROBOTS[0]), 0)
    listener.take_message(pack_message(ROBOTS[1]), 1_000_000_000)
    listener.take_message(pack_message(TeamMessage(team=TEAM + 1, player=3)), 0)
    listener.take_message(b"TF\x01 broken", 0)
    listener.take_game_controller(game_packet(), 1_000_000_000)
    mates = listener.team_mates(2_000_000_000)
    assert [(m.message.player, m.message.x, m.message.role, m.age) for m in mates.mates] == [
        (1, -4100.0, Role.goalkeeper, 2.0), (2, 1200.0, Role.striker, 1.0)]
    assert (mates.received, listener.other_teams, listener.malformed) == (2, 1, 1)
    game = listener.game_state(2_000_000_000)
    assert game.heard and game.state == State.playing and game.team_number == TEAM
    assert not listener.game_state(4_000_000_000).heard  # silent for over 2 s
    assert [m.message.player for m in listener.team_mates(int((FORGET_AFTER_S + 0.5) * 1e9)).mates] == [2]  # player 1 forgotten


def test_a_game_controller_packet_of_another_game_is_not_taken() -> None:
    listener = TeamListener(TEAM + 20)
    listener.take_game_controller(game_packet(), 0)
    assert listener.game is None and not listener.game_state(0).heard


@pytest.fixture(scope="module")
def playwright() -> Iterator[Any]:
    from playwright.sync_api import sync_playwright

    with sync_playwright() as driver:
        yield driver


@pytest.mark.slow
@pytest.mark.skipif(missing_browser() is not None, reason=str(missing_browser()))
def test_tafel_team_shows_two_robots_of_a_team_at_the_poses_their_messages_give(playwright: Any, tmp_path: Path,
                                                                               tmp_path_factory: Any) -> None:
    team_port, game_controller_port = free_udp_port(), free_udp_port()
    program = WebProgram("team", "--team", str(TEAM), "--port", str(team_port), "--game-controller-port", str(game_controller_port),
                         "--web-port", "0", cwd=tmp_path)
    sender = Sender(team_port, game_controller_port)
    browser = launch(playwright)
    try:
        page = open_page(browser, program.url, width=1000, height=900)
        wait_for(page, "tafel.state.team && tafel.state.team.drawn.length === 2 && tafel.state.team.game")
        assert page.evaluate("tafel.state.teamOnly")
        shown = page.evaluate("[...document.querySelectorAll('[data-view]')].filter((p) => p.offsetParent).map((p) => p.dataset.view)")
        assert shown == ["team"]  # no program: the team view alone
        drawn = {d["player"]: d for d in page.evaluate("tafel.state.team.drawn")}
        assert set(drawn) == {1, 2}
        for robot in ROBOTS:
            assert (drawn[robot.player]["x"], drawn[robot.player]["y"]) == (robot.x, robot.y)
            # the canvas holds the robot's role colour in the disc around where its pose puts it
            disc_share = """([x, y, colour]) => {
                const t = tafel.state.team.transform, c = document.querySelector('[data-view=team] canvas');
                const ratio = c.width / c.clientWidth, r = tafel.state.team.radius * t.scale * ratio;
                const px = (t.cx + x * t.scale) * ratio, py = (t.cy - y * t.scale) * ratio;
                const d = c.getContext('2d').getImageData(Math.round(px - r), Math.round(py - r), Math.round(2 * r), Math.round(2 * r)).data;
                let near = 0, all = 0;
                for (let i = 0; i < d.length; i += 4) {
                    const k = i / 4, dx = k % Math.round(2 * r) - r, dy = Math.floor(k / Math.round(2 * r)) - r;
                    if (dx * dx + dy * dy > r * r * 0.8) continue;
                    all++;
                    if (Math.abs(d[i] - colour[0]) < 40 && Math.abs(d[i + 1] - colour[1]) < 40 && Math.abs(d[i + 2] - colour[2]) < 40) near++;
                }
                return near / all; }"""
            colour = list(COLOURS[robot.role.name] if robot.player == 1 else (0x9C, 0xA3, 0xAF))
            deadline = time.monotonic() + 10.0  # the canvas is painted on the next animation frame after the state
            while (share := page.evaluate(disc_share, [robot.x, robot.y, colour])) <= 0.2 and time.monotonic() < deadline:
                time.sleep(0.1)
            assert share > 0.2, f"player {robot.player}: {share:.0%} of its disc in its colour"
        rows = {row.get_attribute("data-player"): row.inner_text() for row in page.locator("[data-view=team] tr[data-player]").all()}
        assert "goalkeeper" in rows["1"] and "keep_goal" in rows["1"] and "playing" in rows["1"]
        assert "striker" in rows["2"] and "fallen" in rows["2"] and "penalized (player_pushing" in rows["2"]
        game = page.inner_text("[data-view=team] .team-game")
        assert "PLAYING" in game and "score 2 : 1" in game and "1130 messages left" in game
        time.sleep(0.5)
        page.locator("[data-view=team]").screenshot(path=str(screenshot_dir(tmp_path_factory) / "team.png"))
        said = json.loads(program.ask("team:robots"))  # the console gets the same
        assert [mate["message"]["player"] for mate in said["TeamMates"]["value"]["mates"]] == [1, 2]
        assert page.problems == []
    finally:
        sender.stop()
        browser.close()
        output, _ = program.stop()
    heard = re.search(r"team 7: (\d+) messages heard, (\d+) malformed", output)
    assert heard and int(heard[1]) >= 2 and int(heard[2]) >= 1, output  # the bytes that were no message counted, not shown
