// The stroke designer: a recipe edited (its force dragged or typed), re-simulated at each change, drawn, heard;
// the notes wanted clicked or typed and designed into a recipe; the recipe and the stroke downloaded.
import {api, chart, download, el, fmt, latest, play, status, stop, svgEl} from "./common.js";
import {openRecipe} from "./palette.js";

const STEP_T = 0.01, STEP_A = 10;  // what an arrow key moves a breakpoint by (s, m/s^2); with Shift a tenth
const NUMBER = {type: "number", step: "any"};

let info = null;            // the presets operation's answer: presets, palette strokes, models, stick, levels
let recipe = null;          // the recipe being edited: exactly its TOML's data
let offset = 0;             // where the recipe's t = 0 falls on the notes' timeline (s; a design's release)
let stroke = null;          // the last simulate answer
let notes = [];             // the notes wanted: {t, level} (s on the timeline, dB)
let nearest = null;         // the last unreachable answer
let cursor = null;          // the playing time (s) or null
let dragging = false;
let changedAt = 0;          // performance.now() of the last change: the time to its drawn stroke is the latency
let built = null;           // resolves once the view is built (a recipe may be sent from the palette before)
const run = latest();
const $ = {};               // the view's elements by name

export function build(section) {
  built = make(section);
  return built;
}

async function make(section) {
  section.classList.add("designer");
  const controls = el("div", {class: "controls"});
  const plots = el("div", {class: "plots"});
  section.append(controls, plots);
  $.start = el("select", {id: "designer-start", "aria-label": "start from"});
  $.model = el("select", {id: "designer-model", onchange: () => edit({model: $.model.value})});
  $.fields = {};
  const recipeRow = el("div", {class: "fields"});
  for (const [key, label] of [["t_end", "t_end (s)"], ["cor", "c"], ["theta0", "θ₀ (rad)"], ["omega0", "ω₀ (rad/s)"]]) {
    $.fields[key] = el("input", {...NUMBER, id: `designer-${key}`, onchange: () => setNumber(key, $.fields[key])});
    recipeRow.append(el("label", {}, label, " ", $.fields[key]));
  }
  $.gravity = el("span", {id: "designer-gravity"});
  $.stick = el("div", {class: "fields"});
  $.terms = el("div", {id: "designer-terms"});
  controls.append(
    el("div", {class: "row"}, el("label", {}, "Start from ", $.start),
       el("button", {id: "designer-load", onclick: () => loadStart()}, "Load")),
    el("div", {class: "row"}, el("label", {}, "Model ", $.model), $.gravity),
    recipeRow,
    el("details", {}, el("summary", {}, "Stick geometry"), $.stick),
    el("h2", {}, "Force a(t), m/s²"),
    $.terms,
    el("div", {class: "row"},
       el("button", {onclick: () => addTerm("piecewise-linear")}, "+ breakpoints"),
       el("button", {onclick: () => addTerm("pulses")}, "+ pulses"),
       el("button", {onclick: () => addTerm("constant")}, "+ constant")),
    notesPanel(),
  );
  $.forcePlot = el("div", {id: "designer-force"});
  $.thetaPlot = el("div", {id: "designer-theta"});
  $.impacts = el("tbody", {id: "designer-impacts"});
  $.summary = el("p", {id: "designer-summary"});
  plots.append(
    $.forcePlot, $.thetaPlot,
    el("div", {class: "row"},
       el("button", {id: "designer-play", onclick: () => playStroke()}, "▶ Play"),
       el("button", {id: "designer-stop", onclick: () => stop()}, "■ Stop"),
       el("button", {id: "designer-toml", onclick: () => fetchFile("toml")}, "Recipe TOML"),
       el("button", {id: "designer-json", onclick: () => fetchFile("json")}, "Stroke JSON"),
       el("button", {id: "designer-csv", onclick: () => fetchFile("csv")}, "Stroke CSV"),
       el("button", {id: "designer-to-palette", onclick: () => openRecipe(recipe, "designed")},
          "Post-process / save in the palette")),
    $.summary,
    el("div", {class: "impacts-box"}, el("table", {class: "impacts"}, el("thead", {}, el("tr", {}, el("th", {}, "#"), el("th", {}, "t (s)"),
                                                      el("th", {}, "level (dB)"), el("th", {}, "tip speed (m/s)"))),
       $.impacts)),
  );
  info = await api("presets");
  for (const m of info.models) $.model.append(el("option", {value: m}, m));
  for (const [group, list] of [["presets", info.presets], ["shipped palette", info.palette]]) {
    const g = el("optgroup", {label: group});
    for (const p of list) g.append(el("option", {value: `${group}:${p.name}`}, `${p.name} — ${p.category}`));
    $.start.append(g);
  }
  $.start.value = "presets:low-high";
  loadStart();
}

// --- the recipe ---------------------------------------------------------------------------------------------------

function loadStart() {
  const [group, name] = $.start.value.split(":");
  const list = group === "presets" ? info.presets : info.palette;
  const chosen = list.find((p) => p.name === name);
  load(structuredClone(chosen.recipe), 0);
  status(`loaded ${name}${group === "presets" ? "" : " (its recipe; the palette's transforms are not applied)"}`);
}

// Load a recipe (and where its t = 0 is on the notes' timeline) and simulate it; the view shown.
export async function openInDesigner(data, name) {
  document.getElementById("tab-designer").click();
  await built;
  load(structuredClone(data), 0);
  status(`opened ${name} in the designer`);
}

function load(data, at = 0) {
  recipe = data;
  offset = at;
  nearest = null;
  fillInputs();
  changed();
}

function fillInputs() {
  $.model.value = recipe.model ?? "paper";
  for (const key of Object.keys($.fields)) $.fields[key].value = recipe[key] ?? {t_end: 5, cor: 0.86, theta0: 0, omega0: 0}[key];
  $.stick.replaceChildren();
  const stick = {...info.stick, ...(recipe.stick || {})};
  for (const [key, value] of Object.entries(stick)) {
    const input = el("input", {...NUMBER, id: `designer-stick-${key}`, value, onchange: () => {
      const v = Number(input.value);
      if (!input.value || !Number.isFinite(v)) return status(`stick.${key} must be a number`, {error: true});
      recipe.stick = {...stick, ...(recipe.stick || {}), [key]: v};
      changed();
    }});
    $.stick.append(el("label", {}, `${key} `, input));
  }
  const g = recipe.gravity ?? {kind: "constant", value: 9.8};
  if (g.kind === "constant") {
    const input = el("input", {...NUMBER, id: "designer-g", value: g.value, onchange: () => {
      const v = Number(input.value);
      if (!input.value || !Number.isFinite(v)) return status("gravity must be a number", {error: true});
      recipe.gravity = {kind: "constant", value: v};
      changed();
    }});
    $.gravity.replaceChildren(el("label", {}, "g (m/s²) ", input));
  } else {
    $.gravity.replaceChildren(`gravity: ${g.kind} (kept as loaded)`);
  }
  drawTerms();
}

function edit(changes) {
  Object.assign(recipe, changes);
  changed();
}

function setNumber(key, input) {
  const v = Number(input.value);
  if (!input.value || !Number.isFinite(v)) return status(`${key} must be a number`, {error: true});
  edit({[key]: v});
}

// The force's terms: the force itself, or a sum's parts. Each is edited by its kind.
function terms() {
  return recipe.force.kind === "sum" ? recipe.force.parts : [recipe.force];
}

function setTerms(list) {
  recipe.force = list.length === 1 ? list[0] : {kind: "sum", parts: list};
}

function addTerm(kind) {
  const end = recipe.t_end ?? 5;
  const made = {
    "piecewise-linear": {kind, points: [[0, 0], [end / 2, 100]]},
    pulses: {kind, amplitude: 150, period: 0.4, duty: 0.05, phase: 0, base: 0},
    constant: {kind, value: 50},
  }[kind];
  setTerms([...terms(), made]);
  drawTerms();
  changed();
}

function removeTerm(i) {
  const list = terms();
  if (list.length === 1) return status("the force needs at least one term", {error: true});
  list.splice(i, 1);
  setTerms(list);
  drawTerms();
  changed();
}

function drawTerms() {
  $.terms.replaceChildren();
  terms().forEach((term, i) => {
    const box = el("fieldset", {class: "term"}, el("legend", {}, `${term.kind}`));
    if (terms().length > 1) box.append(el("button", {class: "remove", "aria-label": `remove term ${i + 1}`,
                                                     onclick: () => removeTerm(i)}, "remove"));
    if (term.kind === "piecewise-linear") box.append(pointsTable(term));
    else if (term.kind === "pulses" || term.kind === "constant") {
      const keys = term.kind === "pulses" ? ["amplitude", "period", "duty", "phase", "base"] : ["value"];
      const row = el("div", {class: "fields"});
      for (const key of keys) {
        const input = el("input", {...NUMBER, id: `designer-term${i}-${key}`, value: term[key] ?? 0, onchange: () => {
          const v = Number(input.value);
          if (!input.value || !Number.isFinite(v)) return status(`force.${key} must be a number`, {error: true});
          term[key] = v;
          changed();
        }});
        row.append(el("label", {}, `${key} `, input));
      }
      box.append(row);
    } else box.append(el("p", {}, "edited as loaded: ", el("code", {}, JSON.stringify(term).slice(0, 200))));
    $.terms.append(box);
  });
}

function pointsTable(term) {
  const body = el("tbody");
  term.points.forEach(([t, a], k) => {
    const cell = (j, value, label) => {
      const input = el("input", {...NUMBER, value, "aria-label": `${label} of point ${k + 1}`, class: `point-${j}`,
                                 onchange: () => {
        const v = Number(input.value);
        if (!input.value || !Number.isFinite(v)) return status(`force.points[${k}] must be numbers`, {error: true});
        term.points[k][j] = v;
        changed();
      }});
      return el("td", {}, input);
    };
    body.append(el("tr", {}, cell(0, t, "t"), cell(1, a, "a"),
                   el("td", {}, el("button", {"aria-label": `remove point ${k + 1}`, onclick: () => removePoint(term, k)},
                                   "×"))));
  });
  return el("div", {}, el("table", {class: "points"},
                          el("thead", {}, el("tr", {}, el("th", {}, "t (s)"), el("th", {}, "a (m/s²)"), el("th"))), body),
            el("button", {class: "add-point", onclick: () => addPoint(term)}, "+ point"));
}

function addPoint(term, at = null) {
  const pts = term.points, end = recipe.t_end ?? 5;
  if (at) {
    const k = pts.findIndex(([t]) => t > at.t);
    pts.splice(k < 0 ? pts.length : k, 0, [at.t, at.a]);
  } else {
    const [t, a] = pts[pts.length - 1];
    pts.push([Math.min(t + Math.max((end - t) / 2, 0.01), Math.max(end, t + 0.01)), a]);
  }
  drawTerms();
  changed();
}

function removePoint(term, k) {
  if (term.points.length === 1) return status("a breakpoint profile needs at least one point", {error: true});
  term.points.splice(k, 1);
  drawTerms();
  changed();
}

// --- simulating and drawing ---------------------------------------------------------------------------------------

function changed() {
  changedAt = performance.now();
  document.body.dataset.designerState = "pending";
  drawForce();
  run(simulateNow);
}

async function simulateNow() {
  const sent = JSON.stringify(recipe);
  try {
    const answer = await api("simulate", {recipe: JSON.parse(sent)});
    if (JSON.stringify(recipe) !== sent) return;  // changed meanwhile: the next run draws it
    stroke = answer;
    drawForce();
    drawTheta();
    document.body.dataset.designerState = "drawn";  // the drawn stroke is the recipe's as it stands
    document.body.dataset.designerLatency = (performance.now() - changedAt).toFixed(1);
    status(`simulated: ${stroke.impacts.t.length} impacts${stroke.rest_time != null ? `, at rest from ${fmt(stroke.rest_time)} s` : ""}`);
  } catch (error) {
    status(error.message, {error: true});
  }
}

function timeRange() {
  return [0, offset + (recipe.t_end ?? 5)];
}

let forceView = null;  // the force chart and its layers, kept while a handle is dragged

function drawForce() {
  if (dragging && forceView) return drawLines();
  const values = terms().flatMap((term) => term.kind === "piecewise-linear" ? term.points.map(([, a]) => a)
    : term.kind === "pulses" ? [term.base ?? 0, (term.base ?? 0) + term.amplitude] : term.kind === "constant" ? [term.value] : []);
  if (stroke) values.push(...stroke.force);
  let low = Math.min(0, ...values), high = Math.max(10, ...values);
  const pad = (high - low) * 0.08;
  const c = chart($.forcePlot, {width: 1000, height: 210, xRange: timeRange(), yRange: [low - pad, high + pad],
                                yLabel: "a (m/s²)", title: "force a(t): drag a handle, or focus it and use the arrow keys; double-click adds a point"});
  forceView = {chart: c, total: c.layer(), lines: c.layer(), handles: c.layer()};
  drawLines();
  c.svg.addEventListener("dblclick", (event) => {
    if (event.target.classList.contains("handle")) return;
    const term = terms().find((x) => x.kind === "piecewise-linear");
    if (!term) return status("add a breakpoints term first", {error: true});
    const p = svgPoint(c.svg, event);
    addPoint(term, {t: Math.max(0, c.fromX(p.x) - offset), a: c.fromY(p.y)});
  });
  drawHandles();
}

function sameClock() {
  return stroke && Math.abs(stroke.t_end - (recipe.t_end ?? 5)) < 1e-12;
}

// The simulated force and each breakpoint term's polyline (redrawn while a handle is dragged; the handles are not).
function drawLines() {
  const {chart: c, total, lines} = forceView;
  total.replaceChildren();
  lines.replaceChildren();
  if (stroke && sameClock()) c.line(stroke.t.map((t) => t + offset), stroke.force, "force", total);
  for (const term of terms()) {
    if (term.kind === "piecewise-linear") {
      c.line(term.points.map(([t]) => t + offset), term.points.map(([, a]) => a), "points", lines);
    }
  }
}

function drawHandles() {
  const {chart: c, handles} = forceView;
  handles.replaceChildren();
  terms().forEach((term, i) => {
    if (term.kind !== "piecewise-linear") return;
    term.points.forEach(([t, a], k) => {
      const handle = svgEl("circle", {cx: c.x(t + offset), cy: c.y(a), r: 7, class: "handle", tabindex: 0,
                                      role: "slider", "data-term": i, "data-point": k, "aria-valuenow": t,
                                      "aria-label": `breakpoint ${k + 1} of term ${i + 1}`,
                                      "aria-valuetext": `t ${fmt(t)} s, a ${fmt(a)} m/s²`});
      handle.addEventListener("pointerdown", (event) => startDrag(event, term, k, handle));
      handle.addEventListener("keydown", (event) => keyMove(event, term, k));
      handles.append(handle);
    });
  });
}

function svgPoint(svg, event) {
  const point = svg.createSVGPoint();
  point.x = event.clientX;
  point.y = event.clientY;
  return point.matrixTransform(svg.getScreenCTM().inverse());
}

// A breakpoint moved to (t, a): kept between its neighbours (1 ms from them) and at t >= 0.
function movePoint(term, k, t, a) {
  const pts = term.points;
  const low = k > 0 ? pts[k - 1][0] + 1e-3 : 0, high = k < pts.length - 1 ? pts[k + 1][0] - 1e-3 : Infinity;
  pts[k] = [+Math.min(Math.max(t, low), high).toFixed(6), +a.toFixed(3)];
}

function startDrag(event, term, k, handle) {
  event.preventDefault();
  handle.setPointerCapture(event.pointerId);
  handle.focus();
  dragging = true;
  const c = forceView.chart;
  const move = (e) => {
    const p = svgPoint(c.svg, e);
    movePoint(term, k, c.fromX(p.x) - offset, c.fromY(p.y));
    handle.setAttribute("cx", c.x(term.points[k][0] + offset));
    handle.setAttribute("cy", c.y(term.points[k][1]));
    changed();
  };
  const end = () => {
    handle.removeEventListener("pointermove", move);
    dragging = false;
    drawTerms();
    drawForce();
  };
  handle.addEventListener("pointermove", move);
  handle.addEventListener("pointerup", end, {once: true});
  handle.addEventListener("pointercancel", end, {once: true});
}

function keyMove(event, term, k) {
  const scale = event.shiftKey ? 0.1 : 1;
  const [t, a] = term.points[k];
  const moves = {ArrowLeft: [-STEP_T, 0], ArrowRight: [STEP_T, 0], ArrowUp: [0, STEP_A], ArrowDown: [0, -STEP_A]};
  if (event.key === "Delete" || event.key === "Backspace") {
    event.preventDefault();
    return removePoint(term, k);
  }
  if (!moves[event.key]) return;
  event.preventDefault();
  const [dt, da] = moves[event.key];
  movePoint(term, k, t + dt * scale, a + da * scale);
  drawTerms();
  changed();
  const again = forceView.handles.querySelector(`[data-term="${terms().indexOf(term)}"][data-point="${k}"]`);
  if (again) again.focus();
}

function level(db) {
  const [low, high] = info.levels;
  return 3 + 9 * Math.min(1, Math.max(0, (db - low) / (high - low)));
}

function drawTheta() {
  if (!stroke) return;
  const t = stroke.t.map((x) => x + offset);
  const thetaMax = stroke.theta_max;
  const high = Math.max(...stroke.theta, thetaMax + 0.1);
  const c = chart($.thetaPlot, {width: 1000, height: 250, xRange: timeRange(), yRange: [thetaMax - 0.05, high + 0.05],
                                xLabel: offset ? `t (s) on the notes' timeline: the recipe's t = 0 at ${fmt(offset)} s` : "t (s)",
                                yLabel: "θ (rad)", title: "θ(t): click to add a note at that time (the level from 'new note level')"});
  const rests = c.layer();
  for (const [a, b] of stroke.rests) c.band(a + offset, b + offset, "rest", rests);
  c.line(timeRange(), [thetaMax, thetaMax], "head");
  if (offset > 0) c.line([0, offset], [stroke.recipe.theta0, stroke.recipe.theta0], "hold");
  c.line(t, stroke.theta, "theta");
  const marks = c.layer("notes");
  for (const note of notes) marks.append(svgEl("circle", {cx: c.x(note.t), cy: c.y(thetaMax), r: level(note.level),
                                                          class: "note"}));
  if (nearest && nearest.nearest_time != null) {
    const x = c.x(nearest.nearest_time);
    marks.append(svgEl("line", {x1: x, x2: x, y1: c.margins.top, y2: c.height - c.margins.bottom, class: "nearest"}));
    const label = svgEl("text", {x: x + 4, y: c.margins.top + 12, class: "nearest"});
    label.textContent = `nearest reachable: ${fmt(nearest.nearest_time)} s`;
    marks.append(label);
  }
  const impacts = stroke.impacts;
  c.dots(impacts.t.map((x) => x + offset), impacts.t.map(() => thetaMax), impacts.level_db.map(level), "impact");
  $.cursor = svgEl("line", {class: "cursor", y1: c.margins.top, y2: c.height - c.margins.bottom, visibility: "hidden"});
  c.svg.append($.cursor);
  $.theta = c;
  moveCursor(cursor);
  c.svg.addEventListener("click", (event) => {
    const p = svgPoint(c.svg, event);
    const at = c.fromX(p.x);
    if (at < 0 || at > timeRange()[1]) return;
    addNote(+at.toFixed(3), Number($.noteLevel.value));
  });
  $.impacts.replaceChildren(...impacts.t.map((x, i) => el("tr", {"data-t": String(x + offset), "data-level": String(impacts.level_db[i])},
    el("td", {}, String(i + 1)), el("td", {}, (x + offset).toFixed(6)), el("td", {}, impacts.level_db[i].toFixed(2)),
    el("td", {}, impacts.tip_speed[i].toFixed(4)))));
  $.summary.textContent = `${impacts.t.length} impacts; the stroke ends at ${fmt(offset + stroke.t_end)} s` +
    (stroke.rest_time != null ? `, at rest from ${fmt(offset + stroke.rest_time)} s` : "") +
    (offset ? `; the recipe's t = 0 is at ${fmt(offset)} s (the release)` : "");
  $.summary.dataset.offset = String(offset);
}

function moveCursor(time) {
  cursor = time;
  if (!$.cursor || !$.theta) return;
  if (time == null) return $.cursor.setAttribute("visibility", "hidden");
  const x = $.theta.x(time);
  $.cursor.setAttribute("x1", x);
  $.cursor.setAttribute("x2", x);
  $.cursor.setAttribute("visibility", "visible");
}

async function playStroke() {
  if (!stroke) return;
  try {
    const wav = await api("stroke_audio", {times: stroke.impacts.t.map((t) => t + offset),
                                           tip_speeds: stroke.impacts.tip_speed});
    status(`playing ${stroke.impacts.t.length} impacts`);
    await play(wav.blob, {onTime: moveCursor});
  } catch (error) {
    status(error.message, {error: true});
  }
}

async function fetchFile(format) {
  try {
    download(await api("stroke_file", {recipe, format}));
    status(`downloaded the ${format === "toml" ? "recipe" : "stroke"} as ${format.toUpperCase()}`);
  } catch (error) {
    status(error.message, {error: true});
  }
}

// --- the notes wanted, and the design that plays them -------------------------------------------------------------

function notesPanel() {
  $.noteLevel = el("input", {...NUMBER, id: "designer-note-level", value: -6});
  $.end = el("select", {id: "designer-end"}, ...["catch", "press", "bounce"].map((e) => el("option", {value: e}, e)));
  $.forceMax = el("input", {...NUMBER, id: "designer-force-max", value: 3000});
  $.notes = el("tbody", {id: "designer-notes"});
  $.problem = el("p", {id: "designer-problem", class: "problem", role: "alert"});
  return el("div", {class: "notes"},
    el("h2", {}, "Notes wanted (the inverse)"),
    el("div", {class: "row"}, el("label", {}, "new note level (dB) ", $.noteLevel), el("label", {}, "end ", $.end),
       el("label", {}, "strongest force (m/s²) ", $.forceMax)),
    el("table", {}, el("thead", {}, el("tr", {}, el("th", {}, "t (s)"), el("th", {}, "level (dB)"), el("th"))), $.notes),
    el("div", {class: "row"},
       el("button", {id: "designer-add-note", onclick: () => {
         const last = notes.length ? notes[notes.length - 1].t : 0.3;
         addNote(+(last + 0.15).toFixed(3), Number($.noteLevel.value));
       }}, "+ note"),
       el("button", {id: "designer-clear-notes", onclick: () => { notes = []; nearest = null; drawNotes(); }}, "Clear"),
       el("button", {id: "designer-design", onclick: () => designNotes()}, "Design")),
    $.problem);
}

function addNote(t, db) {
  notes.push({t, level: Number.isFinite(db) ? db : -6});
  notes.sort((a, b) => a.t - b.t);
  drawNotes();
}

function drawNotes() {
  $.notes.replaceChildren(...notes.map((note, i) => {
    const cell = (key, label) => {
      const input = el("input", {...NUMBER, value: note[key], class: `note-${key}`, "aria-label": `${label} of note ${i + 1}`,
                                 onchange: () => {
        note[key] = Number(input.value);
        input.closest("tr").dataset[key] = input.value;
        drawTheta();
      }});
      return el("td", {}, input);
    };
    return el("tr", {"data-t": String(note.t), "data-level": String(note.level)}, cell("t", "time"), cell("level", "level"),
              el("td", {}, el("button", {"aria-label": `remove note ${i + 1}`, onclick: () => {
                notes.splice(i, 1);
                drawNotes();
              }}, "×")));
  }));
  drawTheta();
}

async function designNotes() {
  const times = notes.map((n) => n.t), levels = notes.map((n) => n.level);
  if (![...times, ...levels].every(Number.isFinite)) return status("every note needs a time and a level", {error: true});
  $.problem.textContent = "";
  nearest = null;
  delete document.body.dataset.designed;
  try {
    const answer = await api("design", {times, levels, end: $.end.value, model: recipe.model ?? "paper",
                                        cor: Math.min(recipe.cor ?? 0.86, 0.99), stick: recipe.stick ?? {},
                                        force_max: Number($.forceMax.value) || 3000});
    if (answer.unreachable) {
      nearest = answer.unreachable;
      const near = [nearest.nearest_time != null ? `t = ${fmt(nearest.nearest_time)} s` : null,
                    nearest.nearest_level != null ? `${fmt(nearest.nearest_level)} dB` : null].filter(Boolean);
      $.problem.textContent = `Unreachable: ${nearest.reason}` + (near.length ? ` (nearest reachable: ${near.join(", ")})` : "");
      $.problem.append(" ", el("button", {id: "designer-use-nearest", onclick: () => useNearest()}, "Use the nearest"));
      status("the notes cannot be played as asked; the nearest reachable is on the chart", {error: true});
      drawTheta();
      document.body.dataset.designed = "unreachable";
      return;
    }
    const made = answer.design;
    recipe = made.recipe;
    offset = made.release;
    stroke = answer.stroke;
    fillInputs();
    drawForce();
    drawTheta();
    status(`designed ${times.length} notes: released at ${fmt(made.release)} s, forces ${fmt(made.force_min)} to ` +
           `${fmt(made.force_max)} m/s²${made.beyond_human ? " (beyond the human thumb)" : ""}; largest errors ` +
           `${made.time_error.toExponential(1)} s, ${made.level_error.toExponential(1)} dB`);
    document.body.dataset.designed = "yes";
  } catch (error) {
    $.problem.textContent = error.message;
    status(error.message, {error: true});
  }
}

function useNearest() {
  const note = notes[nearest.note];
  if (!note) return;
  // rounded away from the unreachable side: the nearest time is the earliest playable, the nearest level the loudest
  if (nearest.nearest_time != null) note.t = Math.ceil(nearest.nearest_time * 1e6) / 1e6;
  else if (nearest.nearest_level != null) note.level = Math.floor(nearest.nearest_level * 1e3) / 1e3;
  nearest = null;
  $.problem.textContent = "";
  drawNotes();
}
