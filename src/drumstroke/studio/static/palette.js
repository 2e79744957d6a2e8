// The palette: the library's strokes as cards (plot, sound, name, category, force); post-processing previewed
// (drawn and heard) before it is saved into the library folder.
import {api, chart, el, fmt, play, status, stop, svgEl} from "./common.js";
import {openInDesigner} from "./designer.js";

let answer = null;     // the palette operation's answer: library, saving, strokes (cards)
let parts = [];        // the stroke being post-processed: [{stroke: SOURCE, steps: [...], label}]
let preview = null;    // the transform operation's answer
let built = null;
const $ = {};

export function build(section) {
  built = make(section);
  return built;
}

async function make(section) {
  section.classList.add("palette");
  $.parts = el("ol", {id: "palette-parts"});
  $.gap = el("input", {type: "number", step: "any", id: "palette-gap", value: 0.2, min: 0, onchange: () => refresh()});
  $.plot = el("div", {id: "palette-preview"});
  $.force = el("div", {id: "palette-force"});
  $.info = el("p", {id: "palette-info"});
  $.name = el("input", {type: "text", id: "palette-name", placeholder: "kebab-case-name", maxlength: 64});
  $.category = el("input", {type: "text", id: "palette-category", placeholder: "category", maxlength: 200});
  $.description = el("input", {type: "text", id: "palette-description", placeholder: "one line", maxlength: 500});
  $.replace = el("input", {type: "checkbox", id: "palette-replace"});
  $.save = el("button", {id: "palette-save", onclick: () => save()}, "Save into the library");
  $.where = el("p", {id: "palette-where"});
  $.cards = el("div", {class: "cards", id: "palette-cards"});
  section.append(
    el("h2", {}, "Post-processing: pick a card's “Post-process” (or “Join” to add it after), add steps, hear, save"),
    $.parts,
    el("div", {class: "steps"}, ...stepControls(),
       el("label", {}, "gap between joined strokes (s) ", $.gap)),
    $.plot, $.force, $.info,
    el("div", {class: "row"},
       el("button", {id: "palette-play", onclick: () => playPreview()}, "▶ Play"),
       el("button", {onclick: () => stop()}, "■ Stop"),
       el("label", {}, "name ", $.name), el("label", {}, "category ", $.category),
       el("label", {}, "description ", $.description),
       el("label", {}, $.replace, " replace a stroke of that name"), $.save),
    $.where,
    el("h2", {}, "Strokes"),
    $.cards,
  );
  await reload();
}

function stepControls() {
  const number = (id, value) => el("input", {type: "number", step: "any", id, value});
  const stretch = number("palette-stretch", 1.5), compress = number("palette-compress", 0.7);
  const t0 = number("palette-trim0", 0), t1 = number("palette-trim1", 0.5), n = number("palette-catch", 1);
  const add = (label, id, step) => el("button", {id, onclick: () => addStep(step())}, label);
  return [
    el("span", {}, add("stretch ×", "palette-add-stretch", () => ({stretch: Number(stretch.value)})), stretch),
    el("span", {}, add("compress ×", "palette-add-compress", () => ({compress: Number(compress.value)})), compress),
    add("reverse", "palette-add-reverse", () => ({reverse: true})),
    el("span", {}, add("trim (s)", "palette-add-trim", () => ({trim: [Number(t0.value), Number(t1.value)]})), t0, t1),
    el("span", {}, add("catch after impact", "palette-add-catch", () => ({catch: Number(n.value)})), n),
  ];
}

async function reload() {
  try {
    answer = await api("palette");
  } catch (error) {
    return status(error.message, {error: true});
  }
  $.where.textContent = answer.saving ? `saving into the library ${answer.library}`
    : "saving is off: start the studio with 'drumstroke studio --library DIR' (a library folder, or a new empty one)";
  $.save.disabled = !answer.saving;
  if (answer.problem) $.where.textContent += ` — the library cannot be read: ${answer.problem}`;
  $.cards.replaceChildren(...answer.strokes.map(card));
  document.body.dataset.paletteCards = String(answer.strokes.length);
  status(`palette: ${answer.strokes.length} strokes`);
}

function source(stroke) {
  return stroke.source === "library" ? {library: stroke.name} : {shipped: stroke.name};
}

function card(stroke) {
  const plot = el("div");
  const box = el("article", {class: "card", "data-name": stroke.name, "data-source": stroke.source},
    el("h3", {}, stroke.name, stroke.source === "library" ? " (library)" : ""),
    el("p", {}, stroke.category || "no category"),
    plot,
    el("p", {}, `${stroke.impacts.t.length} impacts, ${fmt(stroke.t_end)} s`),
    el("p", {}, "force: ", el("code", {}, stroke.recipe ? describe(stroke.recipe.force) : "none stored")),
    el("p", {}, stroke.history.slice(1).length ? `then ${stroke.history.slice(1).join(", ")}` : ""),
    el("div", {class: "row"},
       el("button", {class: "card-play", "aria-label": `play ${stroke.name}`, onclick: () => hear(stroke.impacts, null)}, "▶"),
       el("button", {class: "card-use", onclick: () => use([{stroke: source(stroke), steps: [], label: stroke.name}])},
          "Post-process"),
       el("button", {class: "card-join", onclick: () => use([...parts, {stroke: source(stroke), steps: [], label: stroke.name}])},
          "Join"),
       stroke.recipe ? el("button", {class: "card-open", onclick: () => openInDesigner(stroke.recipe, stroke.name)},
                          "Open in designer") : ""),
  );
  const c = chart(plot, {width: 460, height: 170, xRange: [0, stroke.t_end],
                         yRange: [stroke.theta_max - 0.05, Math.max(...stroke.theta, stroke.theta_max + 0.1) + 0.05]});
  c.line([0, stroke.t_end], [stroke.theta_max, stroke.theta_max], "head");
  c.line(stroke.t, stroke.theta, "theta");
  c.dots(stroke.impacts.t, stroke.impacts.t.map(() => stroke.theta_max), stroke.impacts.level_db.map(radius), "impact");
  c.svg.setAttribute("aria-label", `θ(t) of ${stroke.name}`);
  return box;
}

// A force's table in a few words.
function describe(force) {
  if (force.kind === "constant") return `${fmt(force.value)} m/s²`;
  if (force.kind === "pulses") return `pulses ${fmt(force.amplitude)} m/s² every ${fmt(force.period)} s (duty ${fmt(force.duty)})`;
  if (force.kind === "piecewise-linear") {
    const shown = force.points.slice(0, 6).map(([t, a]) => `(${fmt(t)}, ${fmt(a)})`).join(" ");
    return `breakpoints ${shown}${force.points.length > 6 ? ` … ${force.points.length} points` : ""}`;
  }
  if (force.kind === "sum") return force.parts.map(describe).join(" + ");
  return force.kind;
}

function radius(db) {
  return 2 + 5 * Math.min(1, Math.max(0, (db + 36) / 48));
}

// Post-process what the designer sends (a recipe), shown in the palette.
export async function openRecipe(recipe, label) {
  document.getElementById("tab-palette").click();
  await built;
  use([{stroke: {recipe: structuredClone(recipe)}, steps: [], label}]);
}

function use(list) {
  parts = list;
  if (!$.name.value && list.length === 1) $.name.value = list[0].label.replace(/[^a-z0-9]+/g, "-").replace(/^-|-$/g, "");
  refresh();
}

function addStep(step) {
  if (!parts.length) return status("pick a card's “Post-process” first", {error: true});
  parts[parts.length - 1].steps.push(step);
  refresh();
}

function drawParts() {
  $.parts.replaceChildren(...parts.map((part, i) => el("li", {},
    `${part.label}`, ...part.steps.map((step, k) => {
      const [op, value] = Object.entries(step)[0];
      return el("span", {}, ` → ${op}${op === "reverse" ? "" : ` ${JSON.stringify(value)}`} `,
                el("button", {"aria-label": `remove ${op}`, onclick: () => { part.steps.splice(k, 1); refresh(); }}, "×"));
    }),
    " ", el("button", {"aria-label": `remove ${part.label}`, onclick: () => { parts.splice(i, 1); refresh(); }}, "remove"))));
}

function request() {
  const gap = Number($.gap.value);
  return {parts: parts.map(({stroke, steps}) => ({stroke, steps})), gap: Number.isFinite(gap) ? gap : 0};
}

async function refresh() {
  drawParts();
  delete document.body.dataset.previewed;
  if (!parts.length) {
    preview = null;
    $.plot.replaceChildren();
    $.force.replaceChildren();
    $.info.textContent = "";
    return;
  }
  try {
    preview = await api("transform", request());
  } catch (error) {
    $.info.textContent = error.message;
    return status(error.message, {error: true});
  }
  const p = preview;
  const c = chart($.plot, {width: 1000, height: 150, xRange: [0, p.t_end], xLabel: "t (s)", yLabel: "θ (rad)",
                           yRange: [p.theta_max - 0.05, Math.max(...p.theta, p.theta_max + 0.1) + 0.05],
                           title: "the post-processed stroke (not saved yet)"});
  c.line([0, p.t_end], [p.theta_max, p.theta_max], "head");
  c.line(p.t, p.theta, "theta");
  c.dots(p.impacts.t, p.impacts.t.map(() => p.theta_max), p.impacts.level_db.map((db) => 1.5 * radius(db)), "impact");
  $.cursor = svgEl("line", {class: "cursor", y1: c.margins.top, y2: c.height - c.margins.bottom, visibility: "hidden"});
  c.svg.append($.cursor);
  $.chart = c;
  drawForce(p);
  $.info.textContent = `${p.impacts.t.length} impacts, ${fmt(p.t_end)} s; made by ${p.history.join(", ")}` +
    (p.recipe ? "" : " (joined strokes keep no recipe: the library cannot store them; save the parts)");
  $.info.dataset.impacts = JSON.stringify(p.impacts.t);
  document.body.dataset.previewed = "yes";
  status("previewed: play it, then save it");
}

// The force a(t) where the recipe's force plays (a trimmed or caught stroke's part of it; none for joined strokes).
function drawForce(p) {
  const known = p.force.map((a, i) => (a == null ? null : i)).filter((i) => i != null);
  if (!known.length) return $.force.replaceChildren();
  const values = known.map((i) => p.force[i]);
  const low = Math.min(0, ...values), high = Math.max(10, ...values);
  const c = chart($.force, {width: 1000, height: 80, xRange: [0, p.t_end], yRange: [low, high + 0.05 * (high - low)],
                            yLabel: "a (m/s²)", title: "the force a(t) it plays"});
  let run = [];
  for (const i of [...known, -1]) {  // one line per stretch of samples the recipe plays
    if (run.length && (i < 0 || i !== run[run.length - 1] + 1)) {
      c.line(run.map((k) => p.t[k]), run.map((k) => p.force[k]), "force");
      run = [];
    }
    if (i >= 0) run.push(i);
  }
}

async function hear(impacts, onTime) {
  try {
    const wav = await api("stroke_audio", {times: impacts.t, tip_speeds: impacts.tip_speed});
    await play(wav.blob, {onTime});
  } catch (error) {
    status(error.message, {error: true});
  }
}

function playPreview() {
  if (!preview) return status("nothing to play: pick a card's “Post-process”", {error: true});
  hear(preview.impacts, (time) => {
    if (!$.cursor) return;
    if (time == null) return $.cursor.setAttribute("visibility", "hidden");
    $.cursor.setAttribute("x1", $.chart.x(time));
    $.cursor.setAttribute("x2", $.chart.x(time));
    $.cursor.setAttribute("visibility", "visible");
  });
}

async function save() {
  if (!parts.length) return status("nothing to save: pick a card's “Post-process”", {error: true});
  delete document.body.dataset.saved;
  try {
    const saved = await api("save", {...request(), name: $.name.value.trim(), category: $.category.value,
                                     description: $.description.value, replace: $.replace.checked});
    await reload();
    status(`saved ${saved.saved} into ${saved.library} (${saved.strokes.length} strokes)`);
    document.body.dataset.saved = saved.saved;
  } catch (error) {
    status(error.message, {error: true});
  }
}
