// The field view: the SPL field to scale (field frame: mm, x towards the opponent goal, y to the left,
// rotation counter-clockwise from x), the robot with its cameras' fields of view, the ball model with
// its uncertainty, the ball percept, the ground truth of a simulator, and the "field" and "robot"
// canvases of the debug drawings.

const TAU = Math.PI * 2;
const FIELD_FPS = 15;

export function fieldView(body, connection, state, panel) {
  body.classList.add("field-body");
  const canvas = document.createElement("canvas");
  body.append(canvas);
  const field = { geometry: null, pose: null, ball: null, percept: null, truth: null, drawings: new Map(), cameras: {} };
  state.field = field;

  connection.on("open", async () => {
    try { field.geometry = await connection.json("field:geometry"); } catch (error) { console.warn(error.message); }
    schedule();
  });
  const follow = (topic, key) => panel.follow(topic, (message) => { field[key] = message.value; schedule(); });
  follow("RobotPose", "pose");
  follow("BallModel", "ball");
  follow("BallPercept", "percept");
  for (const camera of ["Top", "Bottom"]) {
    panel.follow(`CameraMatrix${camera}`, { hz: 10 }, (message) => {
      const entry = field.cameras[camera] ||= {};
      entry.rotation = message.value.rotation;
    });
  }
  panel.follow("DebugDrawings", { hz: 15 }, (message) => {
    field.drawings.set(message.context, message.value.primitives.filter((p) => p.canvas === "field" || p.canvas === "robot"));
    schedule();
  });
  // A simulator's ground truth, twice a second, when the platform has it.
  setInterval(async () => {
    if (!connection.connected || !panel.shown() || state.commands?.has("sim:status") === false) return;
    const answer = await connection.ask("sim:status");
    const robot = /robot x=(-?\d+) y=(-?\d+) mm rotation (-?[\d.]+) rad/.exec(answer);
    const ball = /ball x=(-?\d+) y=(-?\d+) mm/.exec(answer);
    field.truth = robot ? { x: +robot[1], y: +robot[2], rotation: +robot[3], ball: ball ? { x: +ball[1], y: +ball[2] } : null } : null;
    schedule();
  }, 500);
  state.hfov = state.hfov || {};

  // Redrawn at most FIELD_FPS times a second, whatever arrives: eyes need no more, and a browser
  // without a graphics card pays for every redraw.
  let queued = false, background = null, drawnAt = 0;
  function schedule() {
    if (queued) return;
    queued = true;
    const wait = Math.max(0, drawnAt + 1000 / FIELD_FPS - performance.now());
    setTimeout(() => requestAnimationFrame(() => { queued = false; drawnAt = performance.now(); draw(); }), wait);
  }
  new ResizeObserver(schedule).observe(body);

  function draw() {
    const g = field.geometry;
    const ratio = window.devicePixelRatio || 1;
    const width = body.clientWidth, height = body.clientHeight;
    if (!g || width < 10 || height < 10) return;
    if (canvas.width !== Math.round(width * ratio) || canvas.height !== Math.round(height * ratio)) {
      canvas.width = Math.round(width * ratio); canvas.height = Math.round(height * ratio);
      background = null;
    }
    const ctx = canvas.getContext("2d");
    const spanX = g.length + 2 * g.border, spanY = g.width + 2 * g.border;
    const scale = Math.min(width / spanX, height / spanY) * ratio;
    state.fieldTransform = { scale: scale / ratio, cx: width / 2, cy: height / 2 };
    // the field itself is drawn once per size, then copied
    if (!background) background = fieldPicture(g, canvas.width, canvas.height, scale);
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.clearRect(0, 0, canvas.width, canvas.height);  // the picture is transparent beside the carpet: old rings stayed there
    ctx.drawImage(background, 0, 0);
    // field frame -> canvas: centre in the middle, y up
    ctx.setTransform(scale, 0, 0, -scale, canvas.width / 2, canvas.height / 2);

    const truth = field.truth;
    if (truth) {
      robot(ctx, truth.x, truth.y, truth.rotation, "rgba(255,255,255,0.55)", true);
      if (truth.ball) circle(ctx, truth.ball.x, truth.ball.y, g.ball_radius, "rgba(255,255,255,0.7)", null);
    }
    const pose = field.pose;
    if (pose) {
      const color = pose.valid ? "#1e4fd8" : "#888";
      for (const [camera, entry] of Object.entries(field.cameras)) {
        if (!entry.rotation) continue;
        const yaw = Math.atan2(entry.rotation[1][0], entry.rotation[0][0]);
        const hfov = state.hfov[camera] || 0.98;
        cone(ctx, pose, yaw, hfov, camera === "Top" ? 3000 : 1000, camera === "Top" ? "rgba(255,255,160,0.22)" : "rgba(160,220,255,0.25)");
      }
      if (pose.deviation < 5000) circle(ctx, pose.x, pose.y, Math.max(pose.deviation, 30), null, "rgba(30,79,216,0.6)", 15);
      robot(ctx, pose.x, pose.y, pose.rotation, color, false);
      // the ball model: the ball with its uncertainty while valid; once it is not (the ball is lost),
      // only a faint ring where it was last believed, never its (by then meaningless) uncertainty
      const ball = field.ball;
      if (ball && ball.valid) {
        const [bx, by] = toField(pose, ball.x, ball.y);
        circle(ctx, bx, by, Math.max(ball.position_std, g.ball_radius), null, "rgba(255,140,0,0.8)", 15);
        circle(ctx, bx, by, g.ball_radius, "#ff8c00", "#000", 8);
      } else if (ball && (ball.x || ball.y)) {
        const [bx, by] = toField(pose, ball.x, ball.y);
        ctx.save(); ctx.setLineDash([25, 25]);
        circle(ctx, bx, by, g.ball_radius, null, "rgba(255,255,255,0.35)", 8);
        ctx.restore();
      }
      const percept = field.percept;
      if (percept && percept.seen) {
        const [px, py] = toField(pose, percept.x, percept.y);
        circle(ctx, px, py, 30, "#e11d48", null);
      }
      state.robot = { x: pose.x, y: pose.y, rotation: pose.rotation, valid: pose.valid };
    }
    for (const primitives of field.drawings.values()) {
      for (const p of primitives) drawPrimitive(ctx, p, p.canvas === "robot" ? pose : null, scale);
    }
    state.fieldDrawn = (state.fieldDrawn || 0) + 1;
  }
}

export function fieldPicture(g, width, height, scale) {
  const picture = new OffscreenCanvas(width, height);
  const ctx = picture.getContext("2d");
  const spanX = g.length + 2 * g.border, spanY = g.width + 2 * g.border;
  ctx.setTransform(scale, 0, 0, -scale, width / 2, height / 2);
  ctx.fillStyle = "#2f8a3a";
  ctx.fillRect(-spanX / 2, -spanY / 2, spanX, spanY);
  ctx.strokeStyle = "#fff"; ctx.lineWidth = g.line_width; ctx.lineCap = "square";
  for (const [x1, y1, x2, y2] of g.lines) line(ctx, x1, y1, x2, y2);
  ctx.beginPath(); ctx.arc(g.circle.x, g.circle.y, g.circle.radius, 0, TAU); ctx.stroke();
  for (const [x, y] of g.marks) { line(ctx, x - g.mark_size / 2, y, x + g.mark_size / 2, y); line(ctx, x, y - g.mark_size / 2, x, y + g.mark_size / 2); }
  ctx.fillStyle = "#fff";
  for (const [x, y] of g.posts) { ctx.beginPath(); ctx.arc(x, y, g.post_radius, 0, TAU); ctx.fill(); }
  return picture;
}

export function toField(pose, x, y) {
  const c = Math.cos(pose.rotation), s = Math.sin(pose.rotation);
  return [pose.x + c * x - s * y, pose.y + s * x + c * y];
}

function line(ctx, x1, y1, x2, y2) { ctx.beginPath(); ctx.moveTo(x1, y1); ctx.lineTo(x2, y2); ctx.stroke(); }

function circle(ctx, x, y, radius, fill, stroke, width = 10) {
  ctx.beginPath(); ctx.arc(x, y, radius, 0, TAU);
  if (fill) { ctx.fillStyle = fill; ctx.fill(); }
  if (stroke) { ctx.strokeStyle = stroke; ctx.lineWidth = width; ctx.stroke(); }
}

function robot(ctx, x, y, rotation, color, dashed) {
  ctx.save();
  ctx.translate(x, y); ctx.rotate(rotation);
  ctx.setLineDash(dashed ? [40, 30] : []);
  ctx.strokeStyle = color; ctx.lineWidth = 25;
  ctx.fillStyle = dashed ? "rgba(0,0,0,0)" : color;
  ctx.beginPath(); ctx.rect(-100, -150, 200, 300);
  if (!dashed) ctx.fill();
  ctx.stroke();
  ctx.beginPath(); ctx.moveTo(100, 0); ctx.lineTo(320, 0); ctx.stroke();
  ctx.restore();
}

function cone(ctx, pose, yaw, hfov, range, fill) {
  const heading = pose.rotation + yaw;
  ctx.beginPath();
  ctx.moveTo(pose.x, pose.y);
  ctx.arc(pose.x, pose.y, range, heading - hfov / 2, heading + hfov / 2);
  ctx.closePath();
  ctx.fillStyle = fill; ctx.fill();
}

// One debug drawing primitive in field coordinates (robot-frame ones moved by the pose), or with
// yUp false in image pixels (y down: text stays upright).
export function drawPrimitive(ctx, p, pose, scale, yUp = true) {
  ctx.save();
  if (pose) { ctx.translate(pose.x, pose.y); ctx.rotate(pose.rotation); }
  ctx.strokeStyle = p.color || "black"; ctx.fillStyle = p.color || "black";
  ctx.lineWidth = (p.width || 1) / scale * (window.devicePixelRatio || 1);
  const q = p.points;
  if (p.kind === "line") line(ctx, q[0], q[1], q[2], q[3]);
  else if (p.kind === "circle") { ctx.beginPath(); ctx.arc(q[0], q[1], q[2], 0, TAU); ctx.stroke(); }
  else if (p.kind === "rectangle") { ctx.strokeRect(q[0], q[1], q[2] - q[0], q[3] - q[1]); }
  else if (p.kind === "robot_pose") { robot(ctx, q[0], q[1], q[2], p.color || "blue", true); }
  else if (p.kind === "text") {
    ctx.translate(q[0], q[1]);
    if (yUp) ctx.scale(1, -1);
    ctx.font = `${(p.width || 12) / scale * (window.devicePixelRatio || 1)}px system-ui`;
    ctx.fillText(p.text, 0, 0);
  }
  ctx.restore();
}
