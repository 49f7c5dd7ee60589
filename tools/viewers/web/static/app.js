// RobotControl in the browser: panels the user arranges (kept in this browser's storage), each a view
// that talks to the program through the debug protocol (connection.js).

import { behaviorView } from "./behavior.js";
import { Connection } from "./connection.js";
import { fieldView } from "./field.js";
import { modulesView } from "./modules.js";
import { teamView } from "./team.js";
import { view3d } from "./view3d.js";
import {
  debugRequestsView, imagesView, logPlayerView, modifyView, parametersView, plotsView, remoteView,
  representationsView, statusView, stopwatchesView,
} from "./views.js";

const VIEWS = [
  { id: "field", title: "Field", make: fieldView, x: 0, y: 0, w: 6, h: 12 },
  { id: "images", title: "Images", make: imagesView, x: 6, y: 0, w: 6, h: 6 },
  { id: "status", title: "Status", make: statusView, x: 6, y: 6, w: 3, h: 6 },
  { id: "remote", title: "Motion remote control", make: remoteView, x: 9, y: 6, w: 3, h: 6, needs: "motion:walk", notOn: "log:play" },
  { id: "log", title: "Log player", make: logPlayerView, x: 0, y: 12, w: 12, h: 2, needs: "log:play" },
  { id: "plots", title: "Plots", make: plotsView, x: 0, y: 14, w: 6, h: 7 },
  { id: "stopwatches", title: "Stopwatches", make: stopwatchesView, x: 6, y: 14, w: 6, h: 7 },
  { id: "modules", title: "Modules", make: modulesView, x: 0, y: 21, w: 8, h: 11 },
  { id: "representations", title: "Representations", make: representationsView, x: 8, y: 21, w: 4, h: 11 },
  { id: "requests", title: "Debug requests", make: debugRequestsView, x: 0, y: 32, w: 4, h: 6 },
  { id: "modify", title: "Modify", make: modifyView, x: 4, y: 32, w: 4, h: 6 },
  { id: "parameters", title: "Parameters", make: parametersView, x: 8, y: 32, w: 4, h: 6 },
  { id: "behavior", title: "Behaviour", make: behaviorView, x: 0, y: 38, w: 12, h: 10 },
  { id: "team", title: "Team", make: teamView, x: 0, y: 48, w: 8, h: 12 },
  { id: "view3d", title: "3D", make: view3d, x: 8, y: 48, w: 4, h: 12 },
];
// `tafel team` serves only the team view (it has team:robots and no program)
const TEAM_ONLY = "team:robots";
const LAYOUT_KEY = "tafel-layout";
const HIDDEN_KEY = "tafel-hidden";

const url = new URL("ws", location.href);
url.protocol = location.protocol === "https:" ? "wss:" : "ws:";
const connection = new Connection(url.href);
const state = { commands: null, panels: {} };
window.tafel = { connection, state };

const saved = JSON.parse(localStorage.getItem(LAYOUT_KEY) || "null") || [];
const hidden = new Set(JSON.parse(localStorage.getItem(HIDDEN_KEY) || "[]"));
const grid = document.getElementById("grid");
const template = document.getElementById("panel");
const menu = document.getElementById("view-list");
const parking = Object.assign(document.createElement("div"), { hidden: true }); // hidden panels wait here
document.body.append(parking);

for (const view of VIEWS) {
  const place = saved.find((item) => item.id === view.id) || view;
  const item = template.content.firstElementChild.cloneNode(true);
  Object.entries({ "gs-id": view.id, "gs-x": place.x, "gs-y": place.y, "gs-w": place.w, "gs-h": place.h })
    .forEach(([key, value]) => item.setAttribute(key, value));
  item.dataset.view = view.id;
  item.querySelector(".panel-title").textContent = view.title;
  const info = item.querySelector(".panel-info");
  const body = item.querySelector(".panel-body");
  const follows = new Set(); // the panel's subscriptions: live only while it is shown and the tab visible
  const panel = {
    item, view, onShow: null,
    shown: () => !item.hidden && document.visibilityState === "visible",
    info: (text) => { info.textContent = text; },
    head: item.querySelector(".panel-head"),
    follow(topic, options, callback) {
      if (typeof options === "function") { callback = options; options = {}; }
      const entry = { topic, options, callback, stop: null };
      follows.add(entry);
      if (panel.shown()) entry.stop = connection.subscribe(topic, options, callback);
      return () => { entry.stop?.(); follows.delete(entry); };
    },
    activate() {
      const live = panel.shown();
      for (const entry of follows) {
        if (live && !entry.stop) entry.stop = connection.subscribe(entry.topic, entry.options, entry.callback);
        if (!live && entry.stop) { entry.stop(); entry.stop = null; }
      }
    },
  };
  state.panels[view.id] = panel;
  item.hidden = hidden.has(view.id) || Boolean(view.needs); // a view that needs commands waits for them
  item.querySelector(".panel-close").onclick = () => show(view.id, false);
  (item.hidden ? parking : grid).append(item);
  try { view.make(body, connection, state, panel); } catch (error) { body.textContent = `this view failed: ${error}`; console.error(error); }
  const box = Object.assign(document.createElement("input"), { type: "checkbox", checked: !hidden.has(view.id), disabled: Boolean(view.needs) });
  box.onchange = () => show(view.id, box.checked);
  panel.box = box;
  const label = document.createElement("label");
  label.append(box, ` ${view.title}`);
  menu.append(label);
}

const gridStack = GridStack.init({
  cellHeight: 44, margin: 4, column: 12, float: false, animate: false, handle: ".panel-head",
  draggable: { handle: ".panel-head", cancel: "input,textarea,button,select,option" },
}, grid);
gridStack.on("change", () => localStorage.setItem(LAYOUT_KEY, JSON.stringify(gridStack.save(false))));

// Show or hide a panel; remember = the user chose it (kept), not the program's commands (not kept).
function show(id, visible, remember = true) {
  const panel = state.panels[id];
  if (remember) {
    visible ? hidden.delete(id) : hidden.add(id);
    localStorage.setItem(HIDDEN_KEY, JSON.stringify([...hidden]));
    panel.box.checked = visible;
  }
  if (visible === !panel.item.hidden) return;
  panel.item.hidden = !visible;
  if (visible) {
    grid.append(panel.item);
    gridStack.makeWidget(panel.item);
    panel.onShow?.();
  } else {
    gridStack.removeWidget(panel.item, false);
    parking.append(panel.item);
  }
  panel.activate();
}

// A tab in the background looks at nothing: it subscribes to nothing.
document.addEventListener("visibilitychange", () => Object.values(state.panels).forEach((panel) => panel.activate()));

document.getElementById("reset-layout").onclick = () => {
  localStorage.removeItem(LAYOUT_KEY);
  localStorage.removeItem(HIDDEN_KEY);
  location.reload();
};

// Connection state, identity, the token form, and which views this program can serve.
const badge = document.getElementById("connection");
const identity = document.getElementById("identity");
const tokenForm = document.getElementById("token-form");
connection.on("open", async (hello) => {
  badge.textContent = "connected"; badge.className = "badge on";
  identity.textContent = hello;
  tokenForm.hidden = true;
  const help = await connection.ask("help");
  state.commands = new Set(help.split("\n").map((line) => line.split(/\s+/)[0]).filter(Boolean));
  state.teamOnly = state.commands.has(TEAM_ONLY);
  for (const view of VIEWS) {
    if (state.teamOnly) { // no program: the team view alone, whatever this browser kept
      state.panels[view.id].box.disabled = true;
      show(view.id, view.id === "team", false);
      if (view.id === "team") gridStack.update(state.panels.team.item, { x: 0, y: 0, w: 12, h: 18 });
      continue;
    }
    if (!view.needs) continue;
    // a view shows where its commands are, and not where they make no sense (a log is watched, not driven)
    const can = state.commands.has(view.needs) && !(view.notOn && state.commands.has(view.notOn));
    state.panels[view.id].box.disabled = !can;
    show(view.id, can && !hidden.has(view.id), false);
  }
  state.ready = true;
  connection.emit("commands");
});
connection.on("close", () => { badge.textContent = "offline"; badge.className = "badge off"; state.ready = false; });
connection.on("auth", () => { tokenForm.hidden = false; identity.textContent = "this program needs its token"; });
tokenForm.onsubmit = async (event) => {
  event.preventDefault();
  const answer = await connection.authenticate(document.getElementById("token").value);
  if (answer !== "authenticated") identity.textContent = answer;
};
