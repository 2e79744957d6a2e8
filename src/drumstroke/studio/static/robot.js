// The robot view: the part editor's part played on the simulated joint by a controller chosen (as 'drumstroke robot
// track' plays a stroke), each stick drawn: the reference and the played angle, the onsets kept and missed.
import {api, chart, el, status, svgEl} from "./common.js";
import {barLines, currentPart, stickLabel, stickOrder} from "./part.js";

let view = null;

export function build(section) {
  const controller = el("select", {id: "robot-controller"});
  const summary = el("ul", {id: "robot-summary"});
  const lanes = el("div", {id: "robot-lanes"});
  view = {controller, summary, lanes};
  section.append(
    el("h2", {}, "Robot"),
    el("p", {class: "note"}, "The part of the part editor, each stick played on the simulated joint (the simple " +
       "plant, 1 kHz). An onset is kept when the joint touches the head within ±2 ms of the reference's audible " +
       "impact."),
    el("div", {class: "row"}, el("label", {}, "Controller ", controller),
       el("button", {id: "robot-track", onclick: () => run()}, "Track the part")),
    summary, lanes);
  api("part_options").then((options) => {
    for (const name of options.controllers) controller.append(el("option", {value: name}, name));
    controller.value = options.controllers.includes("impedance") ? "impedance" : options.controllers[0];
  }).catch((error) => status(error.message, {error: true}));
}

async function run() {
  delete document.body.dataset.tracked;
  status("the robot is playing the part…");
  try {
    const answer = await api("robot", {...currentPart(), controller: view.controller.value || "impedance"});
    draw(answer);
    const kept = Object.values(answer.sticks).reduce((s, v) => s + v.kept, 0);
    const total = Object.values(answer.sticks).reduce((s, v) => s + v.total, 0);
    status(`${answer.controller}: ${kept} of ${total} onsets kept within ±2 ms`);
    document.body.dataset.tracked = String(kept);
  } catch (error) {
    status(error.message, {error: true});
    document.body.dataset.tracked = "error";
  }
}

function draw(answer) {
  const names = stickOrder(answer.sticks);
  const thetas = names.flatMap((name) => [...answer.sticks[name].reference, ...answer.sticks[name].played]);
  const low = Math.min(answer.head, ...thetas), high = Math.max(answer.head, ...thetas);
  const t0 = Math.min(0, ...names.map((name) => answer.sticks[name].t[0]));
  const t1 = Math.max(...names.map((name) => answer.sticks[name].t.at(-1)));
  const pad = 0.08 * (high - low || 1), yRange = [low - pad, high + pad];  // one scale for every stick
  view.lanes.replaceChildren();
  view.summary.replaceChildren();
  for (const name of names) {
    const s = answer.sticks[name], box = el("div", {class: "lane", "data-stick": name}), label = stickLabel(name);
    view.lanes.append(box);
    const c = chart(box, {width: 1300, height: 220, xRange: [t0, t1], yRange, yLabel: "θ (rad)",
                          xLabel: "time (s)", title: `${label} played by ${answer.controller}: reference ` +
                          "(dashed) and played angle; onsets kept ● and missed ✕"});
    barLines(c, answer.bars);
    c.line([t0, t1], [answer.head, answer.head], "head");
    c.line(s.t, s.reference, "reference");
    c.line(s.t, s.played, "played");
    const kept = s.onsets.t.filter((_, i) => s.onsets.kept[i]), missed = s.onsets.t.filter((_, i) => !s.onsets.kept[i]);
    c.dots(kept, kept.map(() => answer.head), 4, "kept onset-kept");
    const marks = c.layer("missed");
    for (const t of missed) {
      const text = svgEl("text", {x: c.x(t), y: c.y(answer.head) + 4, "text-anchor": "middle",
                                  class: "problemtext onset-missed"});
      text.textContent = "✕";
      marks.append(text);
    }
    c.dots(s.extra, s.extra.map(() => answer.head), 2, "extra");
    view.summary.append(el("li", {class: "robot-stick", "data-stick": name, "data-kept": s.kept, "data-total": s.total},
      `${label}: ${s.kept} of ${s.total} onsets kept, ${s.total - s.kept} missed, ${s.extra.length} extra touches; ` +
      `angle error ${s.rms.toFixed(4)} rad rms; peak torque ${s.peak_torque.toFixed(2)} of ${s.torque_limit} N m`));
  }
}
