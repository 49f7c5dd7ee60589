// The modules view: both contexts' graphs in one picture, a lane each (cognition above, motion below):
// modules and the representations between them, laid out by dagre, arrows in the direction data
// flows, the time per module; zoom with the wheel, pan by dragging, "fit" shows everything. Clicking a
// module enables or disables it; providers are chosen above the picture.

import { arg } from "./connection.js";
import { el, every, userChanges } from "./views.js";

const SVG = "http://www.w3.org/2000/svg";
const svg = (tag, attributes = {}) => {
  const node = document.createElementNS(SVG, tag);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, value);
  return node;
};
const LANE_GAP = 28;     // between the lanes
const LANE_HEAD = 22;    // the lane's name above its graph
const READABLE = 0.9;    // the scale a graph opens at when fitting it would make it smaller than this
const MIN_SCALE = 0.05, MAX_SCALE = 4;
const CHAR = 6.6;        // px per character of the 11 px labels (wide enough for system-ui)

export function modulesView(body, connection, state, panel) {
  body.classList.add("graph-body");
  const store = el("button", { type: "button", textContent: "store choices", title: "write providers and disabled modules to the private configuration" });
  const fitButton = el("button", { type: "button", textContent: "fit", title: "show the whole graph" });
  const actual = el("button", { type: "button", textContent: "1:1", title: "full size" });
  const note = el("div");
  const detail = el("div", { className: "row" });
  const providers = el("div", { className: "row providers" });
  const picture = svg("svg", { class: "graph" });
  const defs = svg("defs");
  const arrow = svg("marker", { id: "graph-arrow", viewBox: "0 0 10 10", refX: 10, refY: 5, markerWidth: 7, markerHeight: 7, orient: "auto-start-reverse" });
  arrow.append(svg("path", { d: "M0,0L10,5L0,10z", class: "arrowhead" }));
  defs.append(arrow);
  const viewport = svg("g", { class: "viewport" });
  picture.append(defs, viewport);
  body.append(el("div", { className: "row" }, store, fitButton, actual,
    el("span", { className: "muted", textContent: "wheel: zoom, drag: pan" }), note), detail, providers, picture);
  let graphs = {}, shape = "", selected = null, size = { width: 0, height: 0 }, lanesAt = [];
  const view = { k: 1, x: 0, y: 0, fitted: false, placed: false };
  state.modules = { graphs, view };

  const tell = (answer) => { note.textContent = answer; note.className = answer.startsWith("error:") ? "error" : "ok"; };
  store.onclick = async () => tell(await connection.ask("modules:store"));
  fitButton.onclick = () => fit();
  actual.onclick = () => { view.fitted = false; zoomAt(1 / view.k, picture.clientWidth / 2, picture.clientHeight / 2); };

  const clicks = userChanges();
  async function refresh() {
    const current = clicks.asked();
    let answer;
    try { answer = await connection.json("modules:list -format json"); } catch (error) { tell(error.message); return; }
    if (!current()) return;
    graphs = answer;
    state.modules.graphs = graphs;
    draw();
  }

  const contexts = () => Object.entries(graphs).filter(([, graph]) => graph && !graph.error && graph.modules);

  function draw() {
    const lanes = contexts();
    if (!lanes.length) return;
    // providers with a choice, in either context
    providers.replaceChildren(...lanes.flatMap(([context, graph]) => Object.entries(graph.representations)
      .filter(([, info]) => info.alternatives.length > 1)
      .map(([rep, info]) => {
        const choice = el("select", { dataset: { representation: rep, context } },
          ...info.alternatives.map((m) => el("option", { value: m, textContent: m, selected: m === info.provider })));
        choice.onchange = async () => { clicks.changed(); tell(await connection.ask(`modules:provider -representation ${rep} ${arg("module", choice.value)} -context ${context}`)); refresh(); };
        return el("label", { title: `which module provides ${rep} in ${context}` }, `${rep} (${context}) by `, choice);
      })));
    showDetail();
    const now = JSON.stringify(lanes.map(([context, g]) => [context, g.order, g.modules.map((m) => [m.name, m.enabled, m.active, m.errors > 0]), g.representations]));
    if (now === shape) { updateTimes(); return; }
    shape = now;
    layout(lanes);
  }

  function showDetail() {
    const graph = selected && graphs[selected.context];
    const module = graph?.modules?.find((m) => m.name === selected.name);
    if (!module) { detail.replaceChildren(el("span", { className: "muted", textContent: "click a module to enable or disable it" })); return; }
    const box = el("input", { type: "checkbox", checked: module.enabled });
    box.onchange = async () => { clicks.changed(); tell(await connection.ask(`modules:set ${arg("module", module.name)} -enabled ${box.checked} -context ${selected.context}`)); refresh(); };
    const time = module.mean_us != null ? `mean ${(module.mean_us / 1000).toFixed(2)} ms, max ${(module.max_us / 1000).toFixed(2)} ms` : "not running";
    detail.replaceChildren(el("strong", { textContent: `${module.name} (${selected.context})` }), el("label", {}, box, " enabled"),
      el("span", { className: module.errors ? "error" : "muted", textContent: `${time}${module.errors ? `, ${module.errors} errors: ${module.last_error}` : ""}` }));
  }

  // One dagre layout per context, stacked as lanes.
  function layout(lanes) {
    const provided = new Map(); // representation -> the contexts that provide it
    for (const [context, graph] of lanes) {
      for (const m of graph.modules) for (const r of m.provides) provided.set(r, new Set([...(provided.get(r) || []), context]));
    }
    const groups = [];
    lanesAt = [];
    let top = 0, width = 0;
    for (const [context, graph] of lanes) {
      const g = new dagre.graphlib.Graph({ multigraph: true });
      g.setGraph({ rankdir: "LR", nodesep: 10, ranksep: 46, edgesep: 6, marginx: 10, marginy: 8 });
      g.setDefaultEdgeLabel(() => ({}));
      // a representation made in this lane is one node; one that comes from outside it (the platform,
      // the other context) is drawn beside each module that reads it: no edges across the whole lane
      const made = new Set(graph.modules.flatMap((m) => m.provides));
      const repNode = (r, reader) => {
        const id = made.has(r) ? `r:${r}` : `r:${r}@${reader}`;
        if (!g.hasNode(id)) {
          const from = [...(provided.get(r) || [])].filter((c) => c !== context);
          const label = !made.has(r) && from.length ? `${r} ← ${from.join(", ")}` : r;
          g.setNode(id, { label, width: 14 + CHAR * label.length, height: 20, outside: !made.has(r) });
        }
        return id;
      };
      for (const m of graph.modules) {
        g.setNode(`m:${m.name}`, { label: m.name, width: 14 + CHAR * Math.max(m.name.length, 9), height: 34, module: m });
      }
      for (const m of graph.modules) {
        for (const r of m.provides) g.setEdge(`m:${m.name}`, repNode(r, m.name), { kind: "provides" }, `p:${m.name}:${r}`);
        for (const r of m.requires) g.setEdge(repNode(r, m.name), `m:${m.name}`, { kind: "requires" }, `q:${m.name}:${r}`);
        for (const r of m.uses) g.setEdge(repNode(r, m.name), `m:${m.name}`, { kind: "uses" }, `u:${m.name}:${r}`);
      }
      dagre.layout(g);
      const box = g.graph();
      groups.push({ context, g, top: top + LANE_HEAD, width: box.width, height: box.height });
      lanesAt.push({ top: top + LANE_HEAD, height: box.height });
      top += LANE_HEAD + box.height + LANE_GAP;
      width = Math.max(width, box.width);
    }
    size = { width, height: top - LANE_GAP };
    viewport.replaceChildren();
    for (const { context, g, top: laneTop, height } of groups) {
      const lane = svg("g", { class: "lane", transform: `translate(0,${laneTop})` });
      lane.dataset.context = context;
      lane.append(svg("rect", { class: "lane-back", x: 0, y: -LANE_HEAD, width, height: height + LANE_HEAD, rx: 6 }));
      const name = svg("text", { class: "lane-name", x: 8, y: -6 });
      name.textContent = `${context}: ${graphs[context].modules.length} modules`;
      lane.append(name);
      for (const e of g.edges()) {
        const edge = g.edge(e);
        const d = `M${edge.points.map((p) => `${p.x.toFixed(1)},${p.y.toFixed(1)}`).join("L")}`;
        lane.append(svg("path", { d, class: `edge ${edge.kind}`, "marker-end": "url(#graph-arrow)" }));
      }
      for (const id of g.nodes()) {
        const n = g.node(id);
        const group = svg("g", { transform: `translate(${n.x - n.width / 2},${n.y - n.height / 2})` });
        group.append(svg("rect", { width: n.width, height: n.height, rx: n.module ? 3 : 9 }));
        const label = svg("text", { x: 7, y: 14, class: "name" });
        label.textContent = n.label;
        group.append(label);
        if (n.module) {
          const m = n.module;
          group.setAttribute("class", `node module${m.enabled ? "" : " off"}${m.errors ? " error" : ""}`);
          group.dataset.module = m.name;
          group.dataset.context = context;
          group.append(svg("text", { x: 7, y: 28, class: "time" }));
          group.addEventListener("click", () => { if (!dragged) { selected = { context, name: m.name }; showDetail(); } });
        } else {
          group.setAttribute("class", `node rep${n.outside ? " outside" : ""}`);
        }
        lane.append(group);
      }
      viewport.append(lane);
    }
    updateTimes();
    if (!view.placed || view.fitted) opening();
    else apply();
  }

  function updateTimes() {
    for (const group of viewport.querySelectorAll("g.module")) {
      const m = graphs[group.dataset.context]?.modules?.find((x) => x.name === group.dataset.module);
      const time = group.querySelector("text.time");
      if (m && time) time.textContent = m.mean_us != null ? `${(m.mean_us / 1000).toFixed(2)} ms` : (m.enabled ? "idle" : "disabled");
    }
  }

  // --------------------------------------------------------------------------- zoom and pan
  function apply() {
    viewport.setAttribute("transform", `translate(${view.x},${view.y}) scale(${view.k})`);
  }
  function fitScale() {
    const w = picture.clientWidth, h = picture.clientHeight;
    return w > 20 && h > 20 && size.width ? Math.min((w - 8) / size.width, (h - 8) / size.height) : 0;
  }
  function fit() {
    const k = fitScale();
    if (!k) return;
    view.k = k;
    view.x = (picture.clientWidth - size.width * k) / 2;
    view.y = (picture.clientHeight - size.height * k) / 2;
    view.fitted = view.placed = true;
    apply();
  }
  // As it opens: whole if that is readable, else readable from the left, the first lane's middle in
  // the middle of the view (pan to see the rest)
  function opening() {
    const k = fitScale();
    if (!k) return;
    if (k >= READABLE || view.fitted) { fit(); return; }
    const lane = lanesAt[0] || { top: 0, height: 0 };
    const y = Math.min(4, picture.clientHeight / 2 - (lane.top + lane.height / 2) * READABLE);
    Object.assign(view, { k: READABLE, x: 4, y, placed: true, fitted: false });
    apply();
  }
  function zoomAt(factor, px, py) {
    const k = Math.min(MAX_SCALE, Math.max(MIN_SCALE, view.k * factor));
    view.x = px - ((px - view.x) * k) / view.k;
    view.y = py - ((py - view.y) * k) / view.k;
    view.k = k;
    apply();
  }
  picture.addEventListener("wheel", (event) => {
    event.preventDefault();
    const rect = picture.getBoundingClientRect();
    view.fitted = false;
    zoomAt(Math.exp(-event.deltaY * 0.0015), event.clientX - rect.left, event.clientY - rect.top);
  }, { passive: false });
  let drag = null, dragged = false;
  picture.addEventListener("pointerdown", (event) => {
    if (event.button !== 0) return;
    drag = { x: event.clientX, y: event.clientY, vx: view.x, vy: view.y };
    dragged = false;
  });
  window.addEventListener("pointermove", (event) => {
    if (!drag) return;
    const dx = event.clientX - drag.x, dy = event.clientY - drag.y;
    if (!dragged && Math.hypot(dx, dy) < 3) return;
    if (!dragged) picture.setPointerCapture?.(event.pointerId);
    dragged = true;
    view.fitted = false;
    view.x = drag.vx + dx; view.y = drag.vy + dy;
    apply();
  });
  window.addEventListener("pointerup", () => { drag = null; setTimeout(() => { dragged = false; }, 0); });
  new ResizeObserver(() => { if (view.fitted || !view.placed) opening(); }).observe(picture);

  every(2, panel, connection, refresh);
}
