// The views of the page. Each takes the panel's body, the connection and the page's shared state,
// and talks to the program only through debug commands and subscriptions.

import { arg } from "./connection.js";
import { drawPrimitive } from "./field.js";

export const el = (tag, props = {}, ...children) => {
  const { dataset, ...rest } = props;
  const node = Object.assign(document.createElement(tag), rest);
  if (dataset) Object.assign(node.dataset, dataset);
  node.append(...children);
  return node;
};

// Poll `task` every `seconds` while the panel is shown and the page is connected.
export function every(seconds, panel, connection, task) {
  const run = () => { if (connection.connected && panel.shown()) task(); };
  connection.on("open", run);
  panel.onShow = run;
  setInterval(run, seconds * 1000);
}

// A list asked for before the user's last change answers after it and would show the page as it was
// before the click: such answers are dropped (the next refresh comes soon).
export function userChanges() {
  let changes = 0;
  return { changed: () => { changes += 1; }, asked: () => { const at = changes; return () => at === changes; } };
}

function answerNote(node, answer) {
  node.textContent = answer;
  node.className = answer.startsWith("error:") ? "error" : "ok";
}

// ---------------------------------------------------------------------------------------- images
export function imagesView(body, connection, state, panel) {
  const wrap = el("div", { className: "images" });
  body.append(wrap);
  state.images = {};
  // Each image brings the drawings of the frame it was used in (its header's "drawings"): they are
  // drawn over that image and no other.
  for (const camera of ["Top", "Bottom"]) {
    const canvas = el("canvas");
    const caption = el("figcaption", { textContent: `${camera.toLowerCase()} camera` });
    const figure = el("figure", {}, caption, el("div", { className: "stack" }, canvas));
    wrap.append(figure);
    const seen = state.images[camera.toLowerCase()] = { count: 0, times: [], width: 0, height: 0, mouse: null, shownAt: 0 };
    let busy = false;
    panel.follow(`CameraImage${camera}`, async (message) => {
      seen.count += 1;
      const now = performance.now();
      seen.times.push(now);
      while (seen.times.length && now - seen.times[0] > 2000) seen.times.shift();
      state.hfov = state.hfov || {};
      if (message.horizontal_fov) state.hfov[camera] = message.horizontal_fov;
      // shown at most `fps` times a second (decoding and drawing cost the browser), and never two at once
      if (busy || now - seen.shownAt < 1000 / Number(fps.value) - 4) return;
      busy = true;
      seen.shownAt = now;
      try {
        const bitmap = await createImageBitmap(message.jpeg);
        if (canvas.width !== bitmap.width || canvas.height !== bitmap.height) {  // resizing clears and reallocates
          canvas.width = bitmap.width; canvas.height = bitmap.height;
        }
        seen.width = bitmap.width; seen.height = bitmap.height;
        const ctx = canvas.getContext("2d");
        ctx.drawImage(bitmap, 0, 0);
        bitmap.close();
        for (const p of message.drawings || []) drawPrimitive(ctx, p, null, 1, false);
        seen.drawn = (seen.drawn || 0) + 1;
        seen.frame = message.frame;
        seen.drawingsFrame = message.drawings_frame;
      } finally { busy = false; }
      if (now - captionAt > 500) showCaption();  // text changes cost layout and paint: twice a second
    });
    let captionAt = 0;
    const showCaption = () => {
      captionAt = performance.now();
      const rate = seen.times.length > 1 ? (seen.times.length - 1) / ((seen.times.at(-1) - seen.times[0]) / 1000) : 0;
      const mouse = seen.mouse ? `, pixel (${seen.mouse[0]}, ${seen.mouse[1]})` : "";
      caption.textContent = `${camera.toLowerCase()} camera ${seen.width}x${seen.height}, ${rate.toFixed(1)} images/s${mouse}`;
    };
    canvas.addEventListener("mousemove", (event) => {
      const rect = canvas.getBoundingClientRect();
      if (!seen.width) return;
      const scale = Math.min(rect.width / seen.width, rect.height / seen.height);
      const x = Math.floor((event.clientX - rect.left - (rect.width - seen.width * scale) / 2) / scale);
      const y = Math.floor((event.clientY - rect.top - (rect.height - seen.height * scale) / 2) / scale);
      seen.mouse = x >= 0 && y >= 0 && x < seen.width && y < seen.height ? [x, y] : null;
      showCaption();
    });
    canvas.addEventListener("mouseleave", () => { seen.mouse = null; showCaption(); });
  }
  const fps = el("select", { title: "images shown per second (all arrive; a browser without a graphics card pays for each one shown)" },
    ...[5, 10, 15, 30].map((n) => el("option", { value: n, textContent: `${n} fps`, selected: n === 15 })));
  panel.head.insertBefore(fps, panel.head.querySelector(".panel-close"));
}

// ----------------------------------------------------------------------------------------- plots
const PLOT_COLORS = ["#2563eb", "#dc2626", "#16a34a", "#9333ea", "#ea580c", "#0891b2", "#4d7c0f", "#be185d"];

// A number as an axis or the read-out shows it: short, whatever its size.
export function formatNumber(v) {
  if (v == null || !Number.isFinite(v)) return "–";
  const a = Math.abs(v);
  if (a !== 0 && (a >= 1e6 || a < 1e-3)) return v.toExponential(2);
  return String(Number(v.toPrecision(a >= 1000 ? 6 : 4)));
}

// A series' range: uPlot's, but a constant series gets a narrow band around its value (not 0 to 100).
function valueRange(u, min, max) {
  if (min == null || max == null) return [0, 1];
  if (min === max) { const pad = Math.abs(min) * 0.01 || 1; return [min - pad, max + pad]; }
  return uPlot.rangeNum(min, max, 0.1, true);
}

// An axis just wide enough for its longest tick label (negative ones included), as uPlot measures it.
function axisSize(u, values, index, cycle) {
  const axis = u.axes[index];
  if (cycle > 1) return axis._size;
  const longest = (values || []).reduce((a, v) => (String(v).length > a.length ? String(v) : a), "");
  u.ctx.font = axis.font[0];
  return Math.ceil(axis.ticks.size + axis.gap + u.ctx.measureText(longest).width / (window.devicePixelRatio || 1)) + 4;
}

export function plotsView(body, connection, state, panel) {
  const source = el("select", { title: "what to plot" });
  const field = el("select", { title: "a numeric field", hidden: true });
  const add = el("button", { textContent: "add", type: "button" });
  const windowInput = el("input", { type: "number", value: 10, min: 1, max: 600, className: "wide", title: "window (s)" });
  const pause = el("input", { type: "checkbox" });
  const chosen = el("span");
  const area = el("div", { className: "plot-area" });
  const readout = el("div", { className: "plot-readout" });  // uPlot's legend: the values under the mouse
  body.classList.add("plots-body");
  body.append(el("div", { className: "row" }, source, field, add, el("label", {}, "window ", windowInput, " s"),
    el("label", {}, pause, " pause"), chosen), area, readout);
  const series = []; // {label, xs, ys, stop}
  const plotNames = new Set();
  state.plots = { series, names: plotNames };

  // plot() names: the program sends the list when a name is new (and once a second); the values of
  // every frame only while one of them is plotted
  panel.follow("PlotNames", (message) => {
    const before = plotNames.size;
    for (const name of message.value.names) plotNames.add(name);
    if (plotNames.size !== before) fillSources();
  });
  const onPlots = (message) => {
    const t = message.time_ns / 1e9;
    message.value.names.forEach((name, i) => {
      for (const s of series) if (s.plot === name) push(s, t, message.value.values[i]);
    });
  };
  let stopPlots = null;
  function followPlots() {
    const wanted = series.some((s) => s.plot);
    if (wanted && !stopPlots) stopPlots = panel.follow("DebugPlots", onPlots);
    if (!wanted && stopPlots) { stopPlots(); stopPlots = null; }
  }

  let representations = [];
  async function fillSources() {
    const keep = source.value;
    source.replaceChildren(el("option", { value: "", textContent: "plot or representation…" }));
    const plots = el("optgroup", { label: "plot()" });
    for (const name of [...plotNames].sort()) plots.append(el("option", { value: `plot:${name}`, textContent: name }));
    const reps = el("optgroup", { label: "representations" });
    for (const name of representations) reps.append(el("option", { value: `rep:${name}`, textContent: name }));
    source.append(plots, reps);
    source.value = keep;
  }
  connection.on("open", async () => {
    try {
      const lists = await connection.json("representation:list -format json");
      representations = [...new Set(Object.values(lists).flat().map((r) => r.name))].sort();
      fillSources();
    } catch (error) { console.warn(error.message); }
  });

  source.addEventListener("change", () => {
    field.hidden = !source.value.startsWith("rep:");
    if (field.hidden) return;
    const name = source.value.slice(4);
    field.replaceChildren(el("option", { textContent: "waiting for a value…" }));
    const stop = connection.subscribe(name, (message) => {
      stop();
      field.replaceChildren(...numericPaths(message.value).map((path) => el("option", { value: path, textContent: path })));
    });
  });

  add.addEventListener("click", () => addSeries(source.value, field.value));
  function addSeries(what, path) {
    if (!what) return;
    if (what.startsWith("plot:")) {
      const name = what.slice(5);
      series.push({ label: name, plot: name, xs: [], ys: [] });
    } else {
      const rep = what.slice(4);
      if (!path) return;
      const s = { label: `${rep}.${path}`, xs: [], ys: [] };
      s.stop = panel.follow(rep, (message) => {
        const value = path.split(".").reduce((v, key) => (v == null ? v : v[key]), message.value);
        if (typeof value === "number" || typeof value === "boolean") push(s, message.time_ns / 1e9, Number(value));
      });
      series.push(s);
    }
    rebuild();
  }
  state.plots.add = addSeries;

  function push(s, t, v) {
    if (pause.checked || !Number.isFinite(t) || (s.xs.length && t <= s.xs.at(-1))) return;
    s.xs.push(t); s.ys.push(v);
    const keep = Number(windowInput.value) || 10;
    while (s.xs.length && s.xs[0] < t - keep) { s.xs.shift(); s.ys.shift(); }
  }

  // Each series has a scale and an axis of its own (its name, its colour; left and right in turn), so
  // a series of thousands and one of tenths are both readable; the legend below reads out every
  // series under the mouse.
  let plot = null;
  const size = () => ({ width: Math.max(area.clientWidth, 100), height: Math.max(area.clientHeight, 60) });
  function rebuild() {
    followPlots();
    chosen.replaceChildren(...series.map((s, i) => el("button", {
      type: "button", textContent: `${s.label} ×`, title: "remove", style: `color:${PLOT_COLORS[i % PLOT_COLORS.length]}`,
      onclick: () => { series[i].stop?.(); series.splice(i, 1); rebuild(); },
    })));
    plot?.destroy();
    plot = state.plots.chart = null;
    readout.replaceChildren();
    if (!series.length) return;
    const color = (i) => PLOT_COLORS[i % PLOT_COLORS.length];
    plot = state.plots.chart = new uPlot({
      ...size(),
      scales: { x: { time: false }, ...Object.fromEntries(series.map((s, i) => [`y${i}`, { auto: true, range: valueRange }])) },
      cursor: { drag: { x: false, y: false } },
      legend: { live: true, mount: (u, legend) => readout.replaceChildren(legend) },
      axes: [
        { label: "time (s)", labelSize: 18, values: (u, ticks) => ticks.map((t) => t.toFixed(1)) },
        ...series.map((s, i) => ({
          scale: `y${i}`, label: s.label.split(/[.:]/).at(-1), labelSize: 18, stroke: color(i), side: i % 2 ? 1 : 3,
          grid: { show: i === 0 }, ticks: { stroke: color(i) }, size: axisSize,
          values: (u, ticks) => ticks.map(formatNumber),
        })),
      ],
      // the read-out: the values under the mouse, else the newest ones
      series: [{ label: "t (s)", value: (u, v, si, i) => formatNumber(i == null ? newest(u, si) : v) },
        ...series.map((s, i) => ({ label: s.label, scale: `y${i}`, stroke: color(i), width: 1.5, spanGaps: true,
          value: (u, v, si, at) => formatNumber(at == null ? newest(u, si) : v) }))],
    }, joined(), area);
  }
  function joined() {
    return series.length ? uPlot.join(series.map((s) => [s.xs, s.ys])) : [[]];
  }
  function newest(u, index) {
    const values = u.data[index] || [];
    for (let i = values.length - 1; i >= 0; i--) if (values[i] != null) return values[i];
    return null;
  }
  setInterval(() => {
    if (plot && panel.shown() && !pause.checked) plot.setData(joined());
  }, 100);
  new ResizeObserver(() => plot?.setSize(size())).observe(area);
}

// Paths of the numeric fields of a JSON value ("x", "ball.x", "segments.0.length").
export function numericPaths(value, prefix = "") {
  if (typeof value === "number" || typeof value === "boolean") return [prefix];
  if (Array.isArray(value)) return value.length <= 8 ? value.flatMap((v, i) => numericPaths(v, prefix ? `${prefix}.${i}` : `${i}`)) : [];
  if (value && typeof value === "object") return Object.entries(value).flatMap(([k, v]) => numericPaths(v, prefix ? `${prefix}.${k}` : k));
  return [];
}

// ------------------------------------------------------------------------------- debug requests
export function debugRequestsView(body, connection, state, panel) {
  const tree = el("div", { className: "tree" });
  const note = el("div");
  body.append(note, tree);
  const open = new Set();
  const clicks = userChanges();
  async function refresh() {
    const current = clicks.asked();
    let lists;
    try { lists = await connection.json("debug_request:list -format json"); } catch (error) { answerNote(note, error.message); return; }
    if (!current()) return;
    state.debugRequests = lists;
    const root = {};
    for (const [context, requests] of Object.entries(lists)) {
      if (!Array.isArray(requests)) continue;
      for (const request of requests) {
        let node = root;
        const parts = request.name.split(":");
        parts.slice(0, -1).forEach((part) => { node = node[part] ||= {}; });
        node[parts.at(-1)] = { request, context };
      }
    }
    tree.replaceChildren(...render(root, ""));
  }
  function render(node, path) {
    return Object.entries(node).sort().map(([name, child]) => {
      if (child.request) {
        const box = el("input", { type: "checkbox", checked: child.request.on, dataset: { request: child.request.name } });
        box.addEventListener("change", async () => {
          clicks.changed();
          answerNote(note, await connection.ask(`debug_request:set ${arg("name", child.request.name)} -value ${box.checked ? "on" : "off"} -context ${child.context}`));
        });
        return el("div", { className: "leaf", title: child.request.description }, el("label", {}, box, ` ${name}`),
          el("span", { className: "muted", textContent: `  ${child.request.description || ""}` }));
      }
      const key = `${path}/${name}`;
      const details = el("details", { open: open.size === 0 || open.has(key) }, el("summary", { textContent: name }), ...render(child, key));
      details.addEventListener("toggle", () => (details.open ? open.add(key) : open.delete(key)));
      return details;
    });
  }
  every(3, panel, connection, refresh);
}

// ---------------------------------------------------------------------------------------- modify
export function modifyView(body, connection, state, panel) {
  const list = el("div");
  const note = el("div");
  body.append(note, list);
  // by what comes before the name's last ":" (the module: WalkingEngine:step_duration), like the parameters
  async function refresh(force = false) {
    if (!force && list.contains(document.activeElement)) return; // never under the user's fingers
    let lists;
    try { lists = await connection.json("modify:list -format json"); } catch (error) { answerNote(note, error.message); return; }
    if (!force && list.contains(document.activeElement)) return; // the user started typing meanwhile
    const groups = new Map();
    for (const [context, modifies] of Object.entries(lists)) {
      if (!Array.isArray(modifies)) continue;
      for (const m of modifies) {
        const cut = m.name.lastIndexOf(":");
        const group = cut > 0 ? m.name.slice(0, cut) : "";
        const input = el("input", { type: "text", className: "narrow", value: JSON.stringify(m.pinned ? m.pinned_value : m.value), dataset: { modify: m.name } });
        const pin = el("button", { type: "button", textContent: "pin" });
        const release = el("button", { type: "button", textContent: "release", disabled: !m.pinned });
        pin.onclick = async () => { answerNote(note, await connection.ask(`modify:set ${arg("name", m.name)} ${arg("value", input.value)} -context ${context}`)); refresh(true); };
        release.onclick = async () => { answerNote(note, await connection.ask(`modify:release ${arg("name", m.name)} -context ${context}`)); refresh(true); };
        if (!groups.has(group)) groups.set(group, []);
        groups.get(group).push(el("tr", { className: m.pinned ? "pinned" : "" }, el("td", { textContent: m.name.slice(cut + 1), title: m.name }),
          el("td", { className: "num", textContent: JSON.stringify(m.value), title: "published by the code" }),
          el("td", {}, input, pin, release)));
      }
    }
    list.replaceChildren(...[...groups].map(([group, rows]) => el("fieldset", {}, el("legend", { textContent: group || "(no module)" }), el("table", {}, ...rows))));
    if (!groups.size) list.replaceChildren(el("span", { className: "muted", textContent: "no modify values yet: modules publish them with modify(NAME, VALUE)" }));
  }
  every(2, panel, connection, () => refresh());
}

// ------------------------------------------------------------------------------------ parameters
export function parametersView(body, connection, state, panel) {
  const note = el("div");
  const list = el("div");
  const reload = el("button", { type: "button", textContent: "reload" });
  body.append(el("div", { className: "row" }, reload, note), list);
  async function refresh() {
    let lists;
    try { lists = await connection.json("parameter:list -format json"); } catch (error) { answerNote(note, error.message); return; }
    state.parameters = lists;
    const sets = [];
    for (const [context, modules] of Object.entries(lists)) {
      for (const [module, values] of Object.entries(modules || {})) {
        if (module === "error") continue;
        const rows = Object.entries(values).map(([name, value]) => {
          const input = typeof value === "boolean"
            ? el("input", { type: "checkbox", checked: value })
            : el("input", { type: "text", className: "wide", value: typeof value === "string" ? value : JSON.stringify(value) });
          input.dataset.parameter = `${module}.${name}`;
          const set = async () => {
            const text = input.type === "checkbox" ? (input.checked ? "true" : "false") : input.value;
            answerNote(note, await connection.ask(`parameter:set -module ${module} ${arg("name", name)} ${arg("value", text)} -context ${context}`));
          };
          input.addEventListener("change", set);
          return el("tr", {}, el("td", { textContent: name }), el("td", {}, input));
        });
        const store = el("button", { type: "button", textContent: "store", title: "write to the private configuration" });
        store.onclick = async () => answerNote(note, await connection.ask(`parameter:store -module ${module}`));
        sets.push(el("fieldset", {}, el("legend", {}, `${module} `, store), el("table", {}, ...rows)));
      }
    }
    list.replaceChildren(...sets);
  }
  reload.onclick = refresh;
  connection.on("open", refresh);
  panel.onShow = refresh;
}

// -------------------------------------------------------------------------------- representations
export function representationsView(body, connection, state, panel) {
  const select = el("select");
  const tree = el("div", { className: "tree" });
  body.append(el("div", { className: "row" }, select), tree);
  const open = new Set([""]);
  let stop = null, latest = null, shownAt = 0;
  connection.on("open", async () => {
    try {
      const lists = await connection.json("representation:list -format json");
      const names = [...new Set(Object.values(lists).flat().map((r) => r.name))].sort();
      const keep = select.value;
      select.replaceChildren(el("option", { value: "", textContent: "representation…" }), ...names.map((n) => el("option", { value: n, textContent: n })));
      select.value = keep;
    } catch (error) { console.warn(error.message); }
  });
  select.addEventListener("change", () => {
    stop?.();
    tree.replaceChildren();
    latest = null;
    if (!select.value) return;
    stop = panel.follow(select.value, (message) => {
      latest = message;
      state.inspected = message;
      const now = performance.now();
      if (now - shownAt > 200) { shownAt = now; show(); }
    });
  });
  function show() {
    if (!latest) return;
    panel.info(`${latest.context}, frame ${latest.frame}`);
    tree.replaceChildren(...node(latest.value, ""));
  }
  function node(value, path) {
    if (value !== null && typeof value === "object") {
      return Object.entries(value).map(([key, child]) => {
        const here = `${path}/${key}`;
        if (child !== null && typeof child === "object" && Object.keys(child).length) {
          const details = el("details", { open: open.has(here) }, el("summary", { textContent: key }), ...node(child, here));
          details.addEventListener("toggle", () => (details.open ? open.add(here) : open.delete(here)));
          return details;
        }
        return el("div", { className: "leaf" }, el("b", { textContent: `${key}: ` }), format(child));
      });
    }
    return [el("div", { className: "leaf", textContent: format(value) })];
  }
  const format = (v) => (typeof v === "number" && !Number.isInteger(v) ? v.toPrecision(6) : JSON.stringify(v));
}

// ----------------------------------------------------------------------------------- stopwatches
export function stopwatchesView(body, connection, state, panel) {
  const holder = el("div");
  body.append(holder);
  every(1, panel, connection, async () => {
    let lists;
    try { lists = await connection.json("stopwatch:list -format json"); } catch (error) { holder.textContent = error.message; return; }
    state.stopwatches = lists;
    const num = (v) => el("td", { className: "num", textContent: v.toFixed(1) });
    holder.replaceChildren(...Object.entries(lists).map(([context, data]) => el("table", {},
      el("tr", {}, el("th", { textContent: `${context}: ${(data.rate_hz || 0).toFixed(1)} Hz, frame ${data.frame}` }),
        ...["last", "mean", "max", "p95"].map((h) => el("th", { className: "num", textContent: `${h} (µs)` }))),
      ...(data.stopwatches || []).map((s) => el("tr", {}, el("td", { textContent: s.name }), num(s.last_us), num(s.mean_us), num(s.max_us), num(s.p95_us)))),
    ));
  });
}

// ---------------------------------------------------------------------------------------- status
export function statusView(body, connection, state, panel) {
  const identity = el("div");
  const game = el("div", { className: "game" });
  const pose = el("div");
  const rates = el("div");
  const errors = el("div");
  const file = el("input", { type: "text", className: "wide", placeholder: "file.mcap (optional)" });
  const start = el("button", { type: "button", textContent: "start recording" });
  const stop = el("button", { type: "button", textContent: "stop" });
  const recording = el("span");
  const recordRow = el("div", { className: "row" }, recording, file, start, stop);
  const note = el("div");
  body.append(identity, game, pose, rates, errors, recordRow, note);
  connection.on("open", (hello) => { identity.textContent = hello; });
  connection.on("commands", () => refresh());  // the page knows the program's commands: is it a log?
  start.onclick = async () => { answerNote(note, await connection.ask(`log:start${file.value ? " " + arg("file", file.value) : ""}`)); refresh(); };
  stop.onclick = async () => { answerNote(note, await connection.ask("log:stop")); refresh(); };
  // the game (GameState) and where the robot believes it is (RobotPose), twice a second
  game.textContent = "game: no GameState yet";
  panel.follow("GameState", { hz: 2 }, (message) => { game.textContent = gameText(message.value); });
  panel.follow("RobotPose", { hz: 2 }, (message) => { pose.textContent = poseText(message.value); });
  async function refresh() {
    try {
      const watches = await connection.json("stopwatch:list -format json");
      rates.textContent = Object.entries(watches).map(([c, d]) => `${c} ${(d.rate_hz || 0).toFixed(1)} Hz`).join(" · ");
      state.rates = Object.fromEntries(Object.entries(watches).map(([c, d]) => [c, d.rate_hz]));
      const modules = await connection.json("modules:list -format json");
      const failing = Object.values(modules).flatMap((g) => (g.modules || []).filter((m) => m.errors));
      errors.textContent = failing.length ? `module errors: ${failing.map((m) => `${m.name} ${m.errors} (${m.last_error})`).join("; ")}` : "module errors: none";
      errors.className = failing.length ? "error" : "ok";
    } catch (error) { rates.textContent = error.message; }
    // a log is watched, not recorded
    recordRow.hidden = Boolean(state.commands?.has("log:play"));
    if (recordRow.hidden) return;
    const answer = await connection.ask("log:status");
    let status = null;
    try { status = JSON.parse(answer); } catch { /* "recording: not available" */ }
    state.recording = status;
    recording.textContent = status ? (status.recording ? `recording to ${status.file}` : "not recording") : answer;
    start.disabled = !status || status.recording;
    stop.disabled = !status || !status.recording;
  }
  every(1, panel, connection, refresh);
}

// "game: playing (normal, first half, 412 s left) · score 1 : 0 (team 5 vs 12)" from a GameState: the
// own team's score first.
export function gameText(g) {
  const teams = g.teams || [];
  const own = teams.find((t) => t.team_number === g.team_number);
  const other = teams.find((t) => t.team_number !== g.team_number);
  const half = g.first_half ? "first half" : "second half";
  const phase = [g.game_phase, g.set_play && g.set_play !== "none" ? g.set_play : "", half,
    g.secs_remaining ? `${g.secs_remaining} s left` : ""].filter(Boolean).join(", ");
  const score = `score ${own?.score ?? 0} : ${other?.score ?? 0} (team ${g.team_number}${other ? ` vs ${other.team_number}` : ""})`;
  const source = g.heard ? "" : (g.manual ? " · set by hand" : " · no GameController heard");
  return `game: ${g.state} (${phase}) · ${score}${source}`;
}

// "pose x=1200 y=-340 mm, 12°" and whether the localization trusts it.
export function poseText(p) {
  const degrees = Math.round((p.rotation * 180) / Math.PI);
  return `pose x=${Math.round(p.x)} y=${Math.round(p.y)} mm, ${degrees}°${p.valid ? `, ±${Math.round(p.deviation)} mm` : ", not valid"}`;
}

// ------------------------------------------------------------------------------------ log player
export function logPlayerView(body, connection, state, panel) {
  const play = el("button", { type: "button", textContent: "▶ play" });
  const pauseButton = el("button", { type: "button", textContent: "⏸ pause" });
  const back = el("button", { type: "button", textContent: "◀ step" });
  const forward = el("button", { type: "button", textContent: "step ▶" });
  const slider = el("input", { type: "range", min: 0, max: 0, value: 0 });
  const where = el("span", { className: "muted" });
  const note = el("div");
  body.classList.add("log-player");
  body.append(el("div", { className: "row" }, play, pauseButton, back, forward, slider, where), note);
  let dragging = false;
  const command = async (line) => { answerNote(note, await connection.ask(line)); refresh(); };
  play.onclick = () => command("log:play");
  pauseButton.onclick = () => command("log:pause");
  back.onclick = () => command("log:step -count -1");
  forward.onclick = () => command("log:step -count 1");
  slider.addEventListener("input", () => { dragging = true; where.textContent = `frame ${slider.value}`; });
  slider.addEventListener("change", async () => { dragging = false; await command(`log:goto -frame ${slider.value}`); });
  async function refresh() {
    let position;
    try { position = await connection.json("log:position"); } catch (error) { where.textContent = error.message; return; }
    state.log = position;
    const [first, last] = position.frame_range || [0, 0];
    slider.min = first; slider.max = last;
    if (!dragging && position.frame != null) slider.value = position.frame;
    where.textContent = `${position.context} frame ${position.frame ?? "–"} of ${first}…${last}, ${position.paused ? "paused" : "playing"}`;
  }
  every(0.25, panel, connection, refresh);
}

// ------------------------------------------------------------------------- motion remote control
export function remoteView(body, connection, state, panel) {
  const speed = el("input", { type: "number", value: 150, min: 0, max: 300, className: "wide", title: "mm/s" });
  const note = el("div");
  const button = (text, line) => el("button", { type: "button", textContent: text, onclick: async () => answerNote(note, await connection.ask(line())) });
  const v = () => Number(speed.value) || 0;
  body.classList.add("remote");
  body.append(
    el("div", { className: "row" }, el("label", {}, "speed ", speed, " mm/s")),
    el("div", { className: "row" }, button("↶ turn", () => "motion:walk -rotation 0.5"), button("▲ forward", () => `motion:walk -x ${v()}`),
      button("turn ↷", () => "motion:walk -rotation -0.5")),
    el("div", { className: "row" }, button("◀ left", () => `motion:walk -y ${v()}`), button("■ stand", () => "motion:stand"),
      button("right ▶", () => `motion:walk -y ${-v()}`)),
    el("div", { className: "row" }, button("▼ back", () => `motion:walk -x ${-v()}`), button("kick left", () => "motion:kick -foot left"),
      button("kick right", () => "motion:kick -foot right"), button("sit", () => "motion:sit")),
    el("div", { className: "row" }, button("release to the behaviour", () => "motion:release")),
    note,
  );
  panel.info("motion:* commands");
}
