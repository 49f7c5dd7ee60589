// The behaviour view: the active option path (ActivationGraph: option, state, times, parameters), the
// option graph (OptionGraph) laid out by dagre with the active path highlighted, and a strip of the
// states over the last seconds. On a log, a seek back starts the strip anew.

import { el } from "./views.js";

const SVG = "http://www.w3.org/2000/svg";
const svg = (tag, attributes = {}) => {
  const node = document.createElementNS(SVG, tag);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, value);
  return node;
};
const CHAR = 6.6;       // px per character of the 11 px labels
const ROW = 15;         // px per state row in an option's box
const HISTORY_S = 20;   // s of state changes in the strip
const STRIP_ROW = 16;   // px per depth in the strip

// A colour per option/state, the same every time it is drawn.
function colour(text) {
  let hash = 0;
  for (const c of text) hash = (hash * 31 + c.charCodeAt(0)) >>> 0;
  return `hsl(${hash % 360} 60% 78%)`;
}

export function behaviorView(body, connection, state, panel) {
  body.classList.add("behavior-body");
  const path = el("table", { className: "active-path" });
  const picture = svg("svg", { class: "option-graph" });
  const defs = svg("defs");
  const arrow = svg("marker", { id: "option-arrow", viewBox: "0 0 10 10", refX: 10, refY: 5, markerWidth: 7, markerHeight: 7, orient: "auto" });
  arrow.append(svg("path", { d: "M0,0L10,5L0,10z", class: "arrowhead" }));
  defs.append(arrow);
  const viewport = svg("g");
  picture.append(defs, viewport);
  const strip = el("canvas", { className: "history-strip" });
  const changes = el("div", { className: "changes muted" });
  body.append(path, picture, el("div", { className: "muted", textContent: `the last ${HISTORY_S} s` }), strip, changes);
  const seen = state.behavior = { graph: null, active: [], frames: 0, history: [], changes: [] };
  let boxes = new Map(); // option name -> {group, states: Map(state -> rect)}

  panel.follow("OptionGraph", { hz: 1 }, (message) => {
    const shape = JSON.stringify(message.value);
    if (shape === seen.shape) return;
    seen.shape = shape;
    seen.graph = message.value;
    layout(message.value);
    highlight();
  });

  panel.follow("ActivationGraph", (message) => {
    const options = message.value.options || [];
    const t = (message.time_ns ?? 0) / 1e9;
    seen.active = options;
    seen.frame = message.frame;
    seen.frames += 1;
    const last = seen.history.at(-1);
    if (last && t < last.t) { seen.history = []; seen.changes = []; } // a seek back: a new history
    const now = options.map((o) => `${o.name}/${o.state}`);
    const before = seen.history.at(-1)?.path || [];
    if (before.join(">") !== now.join(">")) {
      seen.changes.push({ t, text: changed(before, now) });
      if (seen.changes.length > 6) seen.changes.shift();
    }
    seen.history.push({ t, path: now });
    while (seen.history.length && seen.history[0].t < t - HISTORY_S) seen.history.shift();
    // text and drawing cost layout and paint: ten times a second is enough to read
    const wall = performance.now();
    if (wall - shownAt < 100) return;
    shownAt = wall;
    panel.info(now.join(" › "));
    showPath(options);
    highlight();
    drawStrip(t);
  });
  let shownAt = 0;

  function changed(before, now) {
    const parts = [];
    for (let i = 0; i < Math.max(before.length, now.length); i++) {
      if (before[i] !== now[i]) parts.push(`${before[i] || "–"} → ${now[i] || "–"}`);
    }
    return parts.slice(0, 2).join(", ");
  }

  function showPath(options) {
    const head = el("tr", {}, ...["option", "state", "in option (s)", "in state (s)", "parameters"].map((t) => el("th", { textContent: t })));
    path.replaceChildren(head, ...options.map((o) => el("tr", { dataset: { option: o.name } },
      el("td", { textContent: `${"  ".repeat(o.depth)}${o.name}`, style: `padding-left: ${6 + 12 * o.depth}px` }),
      el("td", { textContent: o.state }),
      el("td", { className: "num", textContent: o.time_in_option.toFixed(1) }),
      el("td", { className: "num", textContent: o.time_in_state.toFixed(1) }),
      el("td", { textContent: o.parameters }))));
    changes.replaceChildren(...seen.changes.slice().reverse().map((c) => el("div", { textContent: `${c.t.toFixed(1)} s  ${c.text}` })));
  }

  // The option graph: a box per option listing its states, an arrow per call.
  function layout(graph) {
    const g = new dagre.graphlib.Graph();
    g.setGraph({ rankdir: "LR", nodesep: 12, ranksep: 40, marginx: 8, marginy: 8 });
    g.setDefaultEdgeLabel(() => ({}));
    for (const o of graph.options) {
      const wide = Math.max(o.name.length + 2, ...o.states.map((s) => s.name.length + 3));
      g.setNode(o.name, { width: 16 + CHAR * wide, height: 22 + ROW * o.states.length, option: o });
    }
    for (const o of graph.options) for (const callee of o.calls) if (g.hasNode(callee)) g.setEdge(o.name, callee);
    dagre.layout(g);
    viewport.replaceChildren();
    boxes = new Map();
    for (const e of g.edges()) {
      const points = g.edge(e).points;
      viewport.append(svg("path", { class: "edge", d: `M${points.map((p) => `${p.x},${p.y}`).join("L")}`, "marker-end": "url(#option-arrow)" }));
    }
    for (const name of g.nodes()) {
      const n = g.node(name);
      const left = n.x - n.width / 2, top = n.y - n.height / 2;
      const group = svg("g", { class: "option", "data-option": name });
      const title = svg("title");
      title.textContent = n.option.doc;
      group.append(title, svg("rect", { x: left, y: top, width: n.width, height: n.height, rx: 4 }));
      const label = svg("text", { x: left + 6, y: top + 14, class: "option-name" });
      label.textContent = name;
      group.append(label);
      const states = new Map();
      n.option.states.forEach((s, i) => {
        const y = top + 20 + ROW * i;
        const row = svg("rect", { x: left + 3, y, width: n.width - 6, height: ROW - 2, rx: 2, class: "state", "data-state": s.name });
        const text = svg("text", { x: left + 8, y: y + 10 });
        text.textContent = `${s.initial ? "▸ " : ""}${s.name}${s.final ? " ◼" : ""}`;
        const tip = svg("title");
        tip.textContent = `${s.doc}${s.to.length ? `\n→ ${s.to.join(", ")}` : ""}`;
        row.append(tip);
        group.append(row, text);
        states.set(s.name, row);
      });
      viewport.append(group);
      boxes.set(name, { group, states });
    }
    const box = g.graph();
    picture.setAttribute("viewBox", `0 0 ${box.width} ${box.height}`);
  }

  function highlight() {
    const active = new Map(seen.active.map((o) => [o.name, o.state]));
    for (const [name, { group, states }] of boxes) {
      group.classList.toggle("active", active.has(name));
      for (const [stateName, row] of states) row.classList.toggle("active", active.get(name) === stateName);
    }
  }

  // One row per depth: each state a coloured stretch of time, its name on it where it fits.
  function drawStrip(t) {
    const depth = Math.max(1, ...seen.history.map((h) => h.path.length));
    const width = strip.clientWidth || 600;
    if (strip.width !== width || strip.height !== depth * STRIP_ROW) { strip.width = width; strip.height = depth * STRIP_ROW; }
    const ctx = strip.getContext("2d");
    ctx.clearRect(0, 0, strip.width, strip.height);
    ctx.font = "10px system-ui, sans-serif";
    const x = (time) => width - (t - time) / HISTORY_S * width;
    for (let row = 0; row < depth; row++) {
      let start = 0;
      for (let i = 1; i <= seen.history.length; i++) {
        const here = seen.history[start].path[row];
        if (i < seen.history.length && seen.history[i].path[row] === here) continue;
        const x0 = x(seen.history[start].t), x1 = i < seen.history.length ? x(seen.history[i].t) : width;
        if (here) {
          ctx.fillStyle = colour(here);
          ctx.fillRect(x0, row * STRIP_ROW, Math.max(1, x1 - x0), STRIP_ROW - 2);
          const label = here.split("/")[1];
          if (ctx.measureText(label).width < x1 - x0 - 4) { ctx.fillStyle = "#1d2330"; ctx.fillText(label, x0 + 2, row * STRIP_ROW + 11); }
        }
        start = i;
      }
    }
  }
}
