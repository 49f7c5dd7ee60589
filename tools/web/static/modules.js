// The modules view: each context's graph (modules and the representations between them, laid out
// by dagre), with the time per module; enabling and disabling modules and choosing providers.

import { arg } from "./connection.js";
import { el, every } from "./views.js";

const SVG = "http://www.w3.org/2000/svg";
const svg = (tag, attributes = {}) => {
  const node = document.createElementNS(SVG, tag);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, value);
  return node;
};

export function modulesView(body, connection, state, panel) {
  body.classList.add("graph-body");
  const context = el("select");
  const store = el("button", { type: "button", textContent: "store choices", title: "write providers and disabled modules to the private configuration" });
  const fit = el("input", { type: "checkbox", checked: true });
  fit.onchange = () => { const root = picture.querySelector("svg"); if (root) root.style.width = fit.checked ? "100%" : `${root.getAttribute("width")}px`; };
  const note = el("div");
  const detail = el("div", { className: "row" });
  const providers = el("table");
  const picture = el("div", { style: "overflow:auto" });
  body.append(el("div", { className: "row" }, context, store, el("label", {}, fit, " fit the graph to the view (off: full size, scroll)"), note), detail, providers, picture);
  let graphs = {}, shape = "", selected = "";
  state.modules = { graphs };

  const tell = (answer) => { note.textContent = answer; note.className = answer.startsWith("error:") ? "error" : "ok"; };
  store.onclick = async () => tell(await connection.ask("modules:store"));
  context.onchange = () => { shape = ""; draw(); };

  async function refresh() {
    try { graphs = await connection.json("modules:list -format json"); } catch (error) { tell(error.message); return; }
    state.modules.graphs = graphs;
    const names = Object.keys(graphs);
    if (context.options.length !== names.length) {
      context.replaceChildren(...names.map((n) => el("option", { value: n, textContent: n })));
    }
    draw();
  }

  function draw() {
    const graph = graphs[context.value || Object.keys(graphs)[0]];
    if (!graph || graph.error) return;
    const name = graph.name;
    // providers with a choice
    providers.replaceChildren(...Object.entries(graph.representations)
      .filter(([, info]) => info.alternatives.length > 1)
      .map(([rep, info]) => {
        const choice = el("select", { dataset: { representation: rep } },
          ...info.alternatives.map((m) => el("option", { value: m, textContent: m, selected: m === info.provider })));
        choice.onchange = async () => { tell(await connection.ask(`modules:provider -representation ${rep} ${arg("module", choice.value)} -context ${name}`)); refresh(); };
        return el("tr", {}, el("td", { textContent: `${rep} is provided by` }), el("td", {}, choice));
      }));
    showDetail(graph);
    const now = JSON.stringify([name, graph.order, graph.modules.map((m) => [m.name, m.enabled, m.active]), graph.representations]);
    if (now === shape) { updateTimes(graph); return; }
    shape = now;
    layout(graph);
  }

  function showDetail(graph) {
    const module = graph.modules.find((m) => m.name === selected);
    if (!module) { detail.replaceChildren(el("span", { className: "muted", textContent: "click a module to enable or disable it" })); return; }
    const box = el("input", { type: "checkbox", checked: module.enabled });
    box.onchange = async () => { tell(await connection.ask(`modules:set ${arg("module", module.name)} -enabled ${box.checked} -context ${graph.name}`)); refresh(); };
    const time = module.mean_us != null ? `mean ${(module.mean_us / 1000).toFixed(2)} ms, max ${(module.max_us / 1000).toFixed(2)} ms` : "not running";
    detail.replaceChildren(el("strong", { textContent: module.name }), el("label", {}, box, " enabled"),
      el("span", { className: module.errors ? "error" : "muted", textContent: `${time}${module.errors ? `, ${module.errors} errors: ${module.last_error}` : ""}` }));
  }

  function layout(graph) {
    const g = new dagre.graphlib.Graph();
    g.setGraph({ rankdir: "LR", nodesep: 8, ranksep: 40, marginx: 8, marginy: 8 });
    g.setDefaultEdgeLabel(() => ({}));
    const reps = new Set();
    for (const m of graph.modules) {
      g.setNode(`m:${m.name}`, { label: m.name, width: 8 + 7 * Math.max(m.name.length, 10), height: 34, module: m });
      for (const r of [...m.provides, ...m.requires, ...m.uses]) reps.add(r);
    }
    for (const r of reps) g.setNode(`r:${r}`, { label: r, width: 8 + 6.2 * r.length, height: 20 });
    for (const m of graph.modules) {
      for (const r of m.provides) g.setEdge(`m:${m.name}`, `r:${r}`, { kind: "provides" });
      for (const r of m.requires) g.setEdge(`r:${r}`, `m:${m.name}`, { kind: "requires" });
      for (const r of m.uses) g.setEdge(`r:${r}`, `m:${m.name}`, { kind: "uses" });
    }
    dagre.layout(g);
    const { width, height } = g.graph();
    const root = svg("svg", { viewBox: `0 0 ${width} ${height}`, width, height });
    root.style.width = fit.checked ? "100%" : `${width}px`;
    root.style.height = "auto";
    for (const e of g.edges()) {
      const points = g.edge(e).points;
      root.append(svg("path", { d: `M${points.map((p) => `${p.x},${p.y}`).join("L")}`, class: g.edge(e).kind }));
    }
    for (const id of g.nodes()) {
      const n = g.node(id);
      const group = svg("g", { transform: `translate(${n.x - n.width / 2},${n.y - n.height / 2})` });
      group.append(svg("rect", { width: n.width, height: n.height, rx: n.module ? 3 : 9 }));
      const label = svg("text", { x: 5, y: n.module ? 14 : 14 });
      label.textContent = n.label;
      group.append(label);
      if (n.module) {
        const m = n.module;
        group.setAttribute("class", `module${m.enabled ? "" : " off"}${m.errors ? " error" : ""}`);
        group.dataset.module = m.name;
        const time = svg("text", { x: 5, y: 28, class: "time" });
        group.append(time);
        group.onclick = () => { selected = m.name; showDetail(graph); };
      } else {
        group.setAttribute("class", "rep");
      }
      root.append(group);
    }
    picture.replaceChildren(root);
    updateTimes(graph);
  }

  function updateTimes(graph) {
    const byName = new Map(graph.modules.map((m) => [m.name, m]));
    for (const group of picture.querySelectorAll("g.module")) {
      const m = byName.get(group.dataset.module);
      const time = group.querySelector("text.time");
      if (m && time) time.textContent = m.mean_us != null ? `${(m.mean_us / 1000).toFixed(2)} ms` : (m.enabled ? "idle" : "disabled");
    }
  }

  every(2, panel, connection, refresh);
}
