// The studio's entry: the tabs (arrow keys move between them) and each view built when first shown.
import * as designer from "./designer.js";
import * as palette from "./palette.js";
import * as part from "./part.js";
import * as robot from "./robot.js";

const VIEWS = {designer, palette, part, robot};
const built = new Set();

function show(name) {
  for (const [key] of Object.entries(VIEWS)) {
    const tab = document.getElementById(`tab-${key}`), panel = document.getElementById(key);
    const on = key === name;
    tab.setAttribute("aria-selected", String(on));
    tab.tabIndex = on ? 0 : -1;
    panel.hidden = !on;
  }
  if (!built.has(name)) {
    built.add(name);
    VIEWS[name].build(document.getElementById(name));
  }
  VIEWS[name].shown?.();
  history.replaceState(null, "", `#${name}`);
}

const names = Object.keys(VIEWS);
for (const name of names) {
  const tab = document.getElementById(`tab-${name}`);
  tab.addEventListener("click", () => show(name));
  tab.addEventListener("keydown", (event) => {
    const step = {ArrowRight: 1, ArrowLeft: -1}[event.key];
    if (!step) return;
    const next = names[(names.indexOf(name) + step + names.length) % names.length];
    show(next);
    document.getElementById(`tab-${next}`).focus();
  });
}
show(names.includes(location.hash.slice(1)) ? location.hash.slice(1) : "designer");
document.body.dataset.ready = "yes";
