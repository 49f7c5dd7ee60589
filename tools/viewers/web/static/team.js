// The team view, as NaoTH's TeamControl: every robot of a team on the field with its pose, role, ball,
// where it is going (its intention: to the ball, to its goal), the time since its last message,
// fallen or penalized, and the GameController's state.
//
// Two sources, one drawing. `tafel team --team N` listens to the team's messages on the network
// (receive only) and sends what it heard as TeamMates and GameState; a running program (each robot of
// a match) sends the teammates it heard (TeamMates) and the page adds the robot itself from its
// RobotPose, PlayerRole, BallModel and FallState.

import { fieldPicture, toField } from "./field.js";
import { el } from "./views.js";

const TAU = Math.PI * 2;
const TEAM_FPS = 10;
const STALE_S = 2;  // a robot silent longer is drawn faded
const RADIUS = 250; // mm: a robot's disc, larger than the robot so that it is seen on the whole field
// A number as text, or a dash for one that is not (a JSON null, say)
const fixed = (value, digits = 0) => (Number.isFinite(value) ? value.toFixed(digits) : "–");
const ROLE_COLOURS = { goalkeeper: "#7c3aed", striker: "#dc2626", supporter: "#2563eb", defender: "#0891b2", none: "#6b7280" };

export function teamView(body, connection, state, panel) {
  body.classList.add("team-body");
  const game = el("div", { className: "team-game" });
  const holder = el("div", { className: "team-field" });
  const canvas = el("canvas");
  holder.append(canvas);
  const table = el("table", { className: "team-robots" });
  body.append(game, holder, table);
  const team = state.team = { geometry: null, mates: [], own: {}, game: null, robots: [], drawn: [], frames: 0, listening: false, radius: RADIUS };

  connection.on("open", async () => {
    try { team.geometry = await connection.json("field:geometry"); } catch (error) { console.warn(error.message); }
    schedule();
  });
  let subscribed = false;
  connection.on("commands", () => {
    if (subscribed) return; // the connection subscribes again by itself after a reconnect
    subscribed = true;
    team.listening = state.commands.has("team:robots");
    panel.follow("TeamMates", { hz: 5 }, (message) => { team.mates = message.value.mates || []; team.frames += 1; schedule(); });
    panel.follow("GameState", { hz: 2 }, (message) => { team.game = message.value; schedule(); });
    if (team.listening) return;
    for (const topic of ["RobotPose", "PlayerRole", "BallModel", "FallState"]) {
      panel.follow(topic, { hz: 10 }, (message) => { team.own[topic] = message.value; schedule(); });
    }
  });

  let queued = false, drawnAt = 0;
  function schedule() {
    if (queued) return;
    queued = true;
    const wait = Math.max(0, drawnAt + 1000 / TEAM_FPS - performance.now());
    setTimeout(() => requestAnimationFrame(() => { queued = false; drawnAt = performance.now(); draw(); }), wait);
  }
  new ResizeObserver(schedule).observe(holder);

  function draw() {
    team.robots = robots(team);
    showGame(game, team);
    showTable(table, team.robots);
    const g = team.geometry;
    const ratio = window.devicePixelRatio || 1;
    const width = holder.clientWidth, height = holder.clientHeight;
    if (!g || width < 10 || height < 10) return;
    if (canvas.width !== Math.round(width * ratio) || canvas.height !== Math.round(height * ratio)) {
      canvas.width = Math.round(width * ratio); canvas.height = Math.round(height * ratio);
      team.background = null;
    }
    const ctx = canvas.getContext("2d");
    const scale = Math.min(width / (g.length + 2 * g.border), height / (g.width + 2 * g.border)) * ratio;
    team.transform = { scale: scale / ratio, cx: width / 2, cy: height / 2 };
    if (!team.background) team.background = fieldPicture(g, canvas.width, canvas.height, scale);
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.clearRect(0, 0, canvas.width, canvas.height);
    ctx.drawImage(team.background, 0, 0);
    ctx.setTransform(scale, 0, 0, -scale, canvas.width / 2, canvas.height / 2);
    team.drawn = [];
    for (const robot of team.robots) {
      drawRobot(ctx, robot, g);
      const t = team.transform;
      team.drawn.push({ player: robot.player, x: robot.x, y: robot.y, px: t.cx + robot.x * t.scale, py: t.cy - robot.y * t.scale });
    }
    // numbers upright, in screen pixels
    ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
    ctx.font = "bold 12px system-ui"; ctx.textAlign = "center"; ctx.textBaseline = "middle"; ctx.fillStyle = "#fff";
    for (const d of team.drawn) ctx.fillText(String(d.player), d.px, d.py);
    team.drawnFrames = (team.drawnFrames || 0) + 1;
  }
}

// Every robot as one record: the teammates heard, and in a program the robot itself.
function robots(team) {
  const list = team.mates.map(({ message: m, age }) => ({
    player: m.player, x: m.x, y: m.y, rotation: m.rotation, poseValid: m.pose_valid, role: m.role, intention: m.intention,
    fallen: m.fallen, penalized: m.penalized, ball: m.ball_seen || m.ball_age >= 0 ? { x: m.ball_x, y: m.ball_y, age: m.ball_age } : null,
    timeToBall: m.time_to_ball, age, own: false,
  }));
  const { RobotPose: pose, PlayerRole: role, BallModel: ball, FallState: fall } = team.own;
  if (pose && team.game) {
    const ballOnField = ball && ball.valid ? toField(pose, ball.x, ball.y) : null;
    list.push({
      player: team.game.player_number, x: pose.x, y: pose.y, rotation: pose.rotation, poseValid: pose.valid,
      role: role?.role || "none", intention: role?.intention || "none",
      fallen: Boolean(fall && !["upright", "staggering"].includes(fall.phase)), penalized: false,
      ball: ballOnField ? { x: ballOnField[0], y: ballOnField[1], age: ball.time_since_seen } : null,
      timeToBall: role?.time_to_ball ?? -1, age: 0, own: true,
    });
  }
  // the GameController's word on penalties counts too (a robot may not have said it yet)
  const teamInfo = (team.game?.teams || []).find((t) => t.team_number === team.game.team_number);
  for (const robot of list) {
    const info = teamInfo?.players?.[robot.player - 1];
    if (info && info.penalty !== "none") { robot.penalized = true; robot.penalty = info.penalty; robot.unpenalisedIn = info.secs_till_unpenalised; }
  }
  return list.sort((a, b) => a.player - b.player);
}

// Where a robot is going, from what it says it does: to the ball, or to its own goal.
function goal(robot, g) {
  if (robot.intention === "play_ball" && robot.ball) return [robot.ball.x, robot.ball.y];
  if (robot.intention === "keep_goal") return [-g.length / 2 + 300, 0];
  return null;
}

function drawRobot(ctx, robot, g) {
  const colour = ROLE_COLOURS[robot.role] || ROLE_COLOURS.none;
  ctx.save();
  ctx.globalAlpha = robot.age > STALE_S ? 0.4 : 1;
  if (robot.ball) {
    ctx.strokeStyle = "rgba(255,140,0,0.6)"; ctx.lineWidth = 12; ctx.setLineDash([40, 40]);
    ctx.beginPath(); ctx.moveTo(robot.x, robot.y); ctx.lineTo(robot.ball.x, robot.ball.y); ctx.stroke();
    ctx.setLineDash([]);
    ctx.beginPath(); ctx.arc(robot.ball.x, robot.ball.y, g.ball_radius, 0, TAU);
    ctx.fillStyle = "#ff8c00"; ctx.fill(); ctx.strokeStyle = "#000"; ctx.lineWidth = 8; ctx.stroke();
  }
  const target = goal(robot, g);
  if (target) arrow(ctx, robot.x, robot.y, target[0], target[1], colour);
  ctx.translate(robot.x, robot.y); ctx.rotate(robot.rotation);
  ctx.beginPath(); ctx.arc(0, 0, RADIUS, 0, TAU);
  ctx.fillStyle = robot.penalized ? "#9ca3af" : colour; ctx.fill();
  ctx.lineWidth = robot.own ? 40 : 20; ctx.strokeStyle = robot.poseValid ? "#111" : "#bbb";
  if (!robot.poseValid) ctx.setLineDash([40, 30]);
  ctx.stroke(); ctx.setLineDash([]);
  ctx.beginPath(); ctx.moveTo(RADIUS, 0); ctx.lineTo(RADIUS + 200, 0); ctx.lineWidth = 40; ctx.strokeStyle = colour; ctx.stroke();
  if (robot.fallen) { // a red cross over a robot on the ground
    const r = RADIUS * 1.1;
    ctx.strokeStyle = "#b91c1c"; ctx.lineWidth = 30;
    ctx.beginPath(); ctx.moveTo(-r, -r); ctx.lineTo(r, r); ctx.moveTo(-r, r); ctx.lineTo(r, -r); ctx.stroke();
  }
  ctx.restore();
}

function arrow(ctx, x1, y1, x2, y2, colour) {
  const angle = Math.atan2(y2 - y1, x2 - x1);
  ctx.strokeStyle = colour; ctx.fillStyle = colour; ctx.lineWidth = 20;
  ctx.beginPath(); ctx.moveTo(x1, y1); ctx.lineTo(x2, y2); ctx.stroke();
  ctx.beginPath(); ctx.moveTo(x2, y2);
  ctx.lineTo(x2 - 120 * Math.cos(angle - 0.4), y2 - 120 * Math.sin(angle - 0.4));
  ctx.lineTo(x2 - 120 * Math.cos(angle + 0.4), y2 - 120 * Math.sin(angle + 0.4));
  ctx.closePath(); ctx.fill();
}

function showGame(node, team) {
  const game = team.game;
  if (!game) { node.textContent = team.listening ? "listening; no GameController heard" : ""; return; }
  const teams = game.teams || [];
  const own = teams.find((t) => t.team_number === game.team_number), other = teams.find((t) => t.team_number !== game.team_number);
  const clock = `${Math.floor(game.secs_remaining / 60)}:${String(Math.abs(game.secs_remaining % 60)).padStart(2, "0")}`;
  node.textContent = !game.heard && !teams.length ? `team ${game.team_number}: no GameController heard`
    : `team ${game.team_number}: ${game.state.toUpperCase()}${game.set_play !== "none" ? ` (${game.set_play})` : ""}`
      + `, ${game.game_phase}, ${game.first_half ? "first" : "second"} half, ${clock} left`
      + (own && other ? `, score ${own.score} : ${other.score}` : "")
      + (own ? `, ${own.message_budget} messages left` : "")
      + (game.heard ? "" : `; GameController silent for ${fixed(game.seconds_since_packet)} s`);
}

function showTable(table, robots) {
  const head = el("tr", {}, ...["#", "role", "intention", "x", "y", "rot °", "ball", "last message", "state"].map((t) => el("th", { textContent: t })));
  const rows = robots.map((r) => el("tr", { dataset: { player: r.player } },
    el("td", { textContent: `${r.player}${r.own ? " (this robot)" : ""}` }),
    el("td", { textContent: r.role }), el("td", { textContent: r.intention }),
    el("td", { className: "num", textContent: fixed(r.x) }), el("td", { className: "num", textContent: fixed(r.y) }),
    el("td", { className: "num", textContent: fixed(r.rotation * 180 / Math.PI) }),
    el("td", { textContent: r.ball ? `${fixed(r.ball.x)}, ${fixed(r.ball.y)} (${r.ball.age >= 0 ? fixed(r.ball.age, 1) + " s" : "never seen"})` : "–" }),
    el("td", { className: "num", textContent: r.own ? "–" : `${fixed(r.age, 1)} s ago` }),
    el("td", { className: r.fallen || r.penalized ? "error" : "ok",
      textContent: [r.fallen && "fallen", r.penalized && `penalized${r.penalty ? ` (${r.penalty}, ${r.unpenalisedIn} s)` : ""}`].filter(Boolean).join(", ") || "playing" })));
  table.replaceChildren(head, ...rows);
}
