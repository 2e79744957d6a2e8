// The part editor: a step grid and its text pattern, kept in sync; the planner's part drawn as a drummer reads it
// (a lane per stick on one angle scale, the sticking, the problems next to their notes); heard with a cursor;
// the files 'drumstroke compose' writes. The part is always the text: the grid writes it, and reads it back when
// it fits the grid. The robot view plays the same part (currentPart()).
// With Kit on, the part is played on the whole kit ('drumstroke compose --kit'): the grid's rows are the kit's
// pieces (the text's piece column), the limbs are the planner's, and the lanes are one per piece.
import {api, chart, download, el, latest, play, status, stop, svgEl} from "./common.js";

const ROWS = [["right", "R"], ["left", "L"], ["auto", "auto"]];
const LEVELS = {normal: 100, accent: 116, ghost: 45};  // MIDI velocities: R, R> and (R) as the sticking writes them
const CYCLE = [null, "normal", "accent", "ghost"];
const STEPS = {"16ths": 4, "8ths": 2, "triplets": 3};  // steps a quarter note
const METERS = ["4/4", "3/4", "2/4", "5/4", "6/8", "7/8", "12/8"];

const grid = {tempo: 100, meter: "4/4", bars: 2, steps: "16ths", cells: new Map()};  // cells: "row:step" -> note
let source = {pattern: ""};  // what plays: {pattern}, {midi, name} or {rudiment, tempo, bars}
let planned = null, model = "paper", pen = "auto";
let kit = false, kitRows = [];  // the kit mode, and its rows: {name (the piece column), piece, state, limbs, also}
let hands = {lead: "right", open_handed: false};  // compose --kit's --lead and --open-handed
let otherCells = null;  // {cells, steps} of the mode not shown (the sticks' or the kit's); null: the kit's not made yet
const queue = latest();
let view = null;  // the DOM of the view once built

// The part the robot view and the requests use: the source and the model.
export function currentPart() {
  return kit ? {...source, model, kit: true, ...hands} : {...source, model};
}

// The grid's rows: [key, label] (the sticks, or the kit's pieces by the name the text's piece column writes).
function gridRows() {
  return kit ? kitRows.map((row) => [row.name, row.name]) : ROWS;
}

// A cell's key "row:step" (a kit's row may hold a colon: "hihat:open") and back.
function cellKey(row, step) {
  return `${row}:${step}`;
}

function keyParts(key) {
  const at = key.lastIndexOf(":");
  return [key.slice(0, at), +key.slice(at + 1)];
}

function barBeats() {
  const [n, d] = grid.meter.split("/").map(Number);
  return 4 * n / d;  // quarter notes a bar
}

function stepCount() {
  return Math.round(barBeats() * STEPS[grid.steps]) * grid.bars;
}

// The grid as a text pattern: the tempo, the meter, one line a note in time order.
function gridText() {
  const lines = [`tempo ${grid.tempo}`];
  if (grid.meter !== "4/4") lines.push(`meter ${grid.meter}`);
  const per = STEPS[grid.steps];
  for (let step = 0; step < stepCount(); step++) {
    for (const [row] of gridRows()) {
      const note = grid.cells.get(cellKey(row, step));
      if (note && kit) lines.push(`${step / per} auto ${LEVELS[note.level]} auto ${row}`);  // limbs: the planner's
      else if (note) lines.push(`${step / per} ${note.stroke} ${LEVELS[note.level]} ${row}`);
    }
  }
  return lines.join("\n") + "\n";
}

// The text read back into the grid when every note fits it (a step of the grid's, a stick of its rows, a level of
// its three, no buzz length, no kit piece, at most 8 bars; on the kit: an auto note on a piece of its rows); else
// null: the text is what plays.
function textGrid(text) {
  let tempo = null, meter = "4/4";
  const notes = [];
  for (const raw of text.split("\n")) {
    const f = raw.split("#")[0].trim().split(/\s+/).filter(Boolean);
    if (!f.length) continue;
    if (tempo === null) {
      if (f[0] !== "tempo" || f.length !== 2 || !(+f[1] > 0)) return null;
      tempo = +f[1];
    } else if (f[0] === "meter") {
      if (!METERS.includes(f[1])) return null;
      meter = f[1];
    } else {
      const note = kit ? kitNote(f) : stickNote(f);
      if (!note) return null;
      notes.push(note);
    }
  }
  if (tempo === null) return null;
  const [n, d] = meter.split("/").map(Number), length = 4 * n / d;
  const last = Math.max(0, ...notes.map((note) => note.beat));
  const bars = Math.max(1, Math.floor(last / length) + 1);
  if (bars > 8) return null;
  const choices = [grid.steps, ...Object.keys(STEPS).filter((name) => name !== grid.steps)];  // the grid's first
  const steps = choices.find((name) => notes.every((note) => {
    const k = note.beat * STEPS[name];
    const bar = length * STEPS[name];
    return Math.abs(k - Math.round(k)) < 1e-9 && Math.abs(bar - Math.round(bar)) < 1e-9;
  }));
  if (!steps) return null;
  const cells = new Map();
  for (const note of notes) {
    const key = cellKey(note.stick, Math.round(note.beat * STEPS[steps]));
    if (cells.has(key)) return null;
    cells.set(key, {level: note.level, stroke: note.stroke});
  }
  return {tempo, meter, bars: Math.max(bars, grid.bars), steps, cells};
}

// A note line's fields as a cell of the sticks' grid, or null.
function stickNote([beat, stroke, velocity, stick = "right", ...rest]) {
  const level = Object.keys(LEVELS).find((k) => LEVELS[k] === +velocity);
  if (rest.length || !level || !ROWS.some(([row]) => row === stick) || !(+beat >= 0)) return null;
  return {beat: +beat, stroke, level, stick};
}

// A note line's fields as a cell of the kit's grid (its row in .stick), or null: an auto note, its limb the
// planner's, on a piece of the rows (none named: the snare, as compose --kit reads it).
function kitNote([beat, stroke, velocity, limb = "right", ...rest]) {
  const level = Object.keys(LEVELS).find((k) => LEVELS[k] === +velocity);
  const piece = rest.length === 1 ? rest[0] : "snare";
  const row = kitRows.find((r) => r.name === piece || r.also.includes(piece));
  if (rest.length > 1 || stroke !== "auto" || limb !== "auto" || !level || !row || !(+beat >= 0)) return null;
  return {beat: +beat, stroke, level, stick: row.name};
}

// A groove on the kit: the hi-hat's 8ths, the snare's backbeat accented, the kick on 1 and 3.
function kitGroove() {
  const cells = new Map(), per = STEPS[grid.steps];
  const set = (row, step, level) => {
    if (kitRows.some((r) => r.name === row)) cells.set(cellKey(row, step), {level, stroke: "auto"});
  };
  for (let step = 0; step < stepCount(); step++) {
    const beat = step / per, quarter = beat % 4;
    if (Number.isInteger(beat * 2)) set("hihat", step, "normal");
    if (quarter === 1 || quarter === 3) set("snare", step, "accent");
    if (quarter === 0 || quarter === 2) set("kick", step, "normal");
  }
  return cells;
}

function defaultGroove() {  // a backbeat groove on 8ths: the hands alternating, the accents on 2 and 4
  for (let step = 0; step < stepCount(); step += 2) {
    const quarter = (step / STEPS[grid.steps]) % 4;
    grid.cells.set(`${step % 4 === 0 ? "right" : "left"}:${step}`,
                   {level: quarter === 1 || quarter === 3 ? "accent" : "normal", stroke: "auto"});
  }
}

defaultGroove();
source = {pattern: gridText()};

export function build(section) {
  const tempo = el("input", {type: "number", id: "part-tempo", min: 20, max: 400, step: 1, value: grid.tempo});
  const meter = el("select", {id: "part-meter"}, ...METERS.map((m) => el("option", {value: m}, m)));
  const bars = el("select", {id: "part-bars"}, ...[1, 2, 3, 4, 5, 6, 7, 8].map((b) => el("option", {value: b}, b)));
  const steps = el("select", {id: "part-steps"}, ...Object.keys(STEPS).map((s) => el("option", {value: s}, s)));
  const penSelect = el("select", {id: "part-pen"}, el("option", {value: "auto"}, "auto (the planner designs it)"),
                       el("option", {value: "buzz"}, "buzz"));
  const modelSelect = el("select", {id: "part-model"}, el("option", {value: "paper"}, "paper"),
                         el("option", {value: "geometry"}, "geometry"));
  const rudiment = el("select", {id: "part-rudiment", "aria-label": "rudiment"});
  const rudimentTempo = el("input", {type: "number", id: "part-rudiment-tempo", min: 20, max: 400, value: 100,
                                     "aria-label": "rudiment tempo (bpm)"});
  const midi = el("input", {type: "file", id: "part-midi", accept: ".mid,.midi,audio/midi"});
  const text = el("textarea", {id: "part-text", spellcheck: "false", "aria-label": "the part as a text pattern"});
  const fits = el("p", {id: "part-fits", class: "note"});
  const table = el("div", {id: "part-grid", class: "stepgrid", role: "grid", "aria-label": "step grid"});
  const lanes = el("div", {id: "part-lanes"});
  const problems = el("ul", {id: "part-problems", class: "problems"});
  const sticking = el("p", {id: "part-sticking", class: "sticking"});
  const playButton = el("button", {id: "part-play", onclick: () => hear()}, "▶ Play");
  const downloads = el("span", {class: "row"}, "Download:",
                       ...[["csv", "CSV"], ["json", "JSON"], ["midi", "MIDI"], ["wav", "WAV"], ["ros", "ROS JSON"],
                           ["plot", "plot (PNG)"], ["pattern", "pattern"]].map(([kind, label]) =>
                         el("button", {id: `part-download-${kind}`, onclick: () => take(kind),
                                       hidden: kind === "plot"}, label)));
  const kitSwitch = el("input", {type: "checkbox", id: "part-kit", disabled: true});
  const lead = el("select", {id: "part-lead"}, el("option", {value: "right"}, "right"),
                  el("option", {value: "left"}, "left"));
  const openHanded = el("input", {type: "checkbox", id: "part-open-handed"});
  const kitOptions = el("span", {class: "row", hidden: true}, el("label", {}, "Lead hand ", lead),
                        el("label", {}, openHanded, " open-handed"));
  view = {tempo, meter, bars, steps, text, fits, table, lanes, problems, sticking, rudiment, rudimentTempo, penSelect,
          downloads, kitOptions};
  section.append(
    el("h2", {}, "Part editor"),
    el("div", {class: "row"},
       el("label", {title: "play the part on the whole kit (drumstroke compose --kit): a row per piece"}, kitSwitch,
          " Kit"), kitOptions),
    el("div", {class: "row"}, el("label", {}, "Tempo (bpm) ", tempo), el("label", {}, "Meter ", meter),
       el("label", {}, "Bars ", bars), el("label", {}, "Steps ", steps),
       el("label", {}, "Stroke of new notes ", penSelect), el("label", {}, "Model ", modelSelect)),
    el("div", {class: "row"}, el("label", {}, "Start from a rudiment ", rudiment),
       el("label", {}, "at ", rudimentTempo, " bpm"),
       el("button", {id: "part-rudiment-load", onclick: () => loadRudiment()}, "Load"),
       el("label", {}, "or a MIDI file (drop it on the grid) ", midi)),
    el("p", {class: "note"}, "Click a cell (or Enter, Space; arrow keys move): off → normal → accent > → " +
       "ghost ( ) → off. A note takes the stroke of new notes when it is set."),
    table,
    el("div", {class: "row"},
       el("button", {id: "part-clear", onclick: () => { grid.cells.clear(); edited(); }}, "Clear the grid"),
       playButton, el("button", {id: "part-stop", onclick: () => stop()}, "■ Stop"), downloads),
    sticking, lanes, problems,
    el("details", {open: true}, el("summary", {}, "Text pattern (edit it: the grid follows when it fits)"),
       text, fits));
  meter.value = grid.meter; bars.value = grid.bars; steps.value = grid.steps;
  tempo.addEventListener("change", () => { grid.tempo = +tempo.value; edited(); });
  meter.addEventListener("change", () => { grid.meter = meter.value; trim(); edited(); });
  bars.addEventListener("change", () => { grid.bars = +bars.value; trim(); edited(); });
  steps.addEventListener("change", () => { resample(steps.value); edited(); });
  penSelect.addEventListener("change", () => { pen = penSelect.value; });
  kitSwitch.addEventListener("change", () => setKit(kitSwitch.checked));
  lead.addEventListener("change", () => { hands = {...hands, lead: lead.value}; replan(); });
  openHanded.addEventListener("change", () => { hands = {...hands, open_handed: openHanded.checked}; replan(); });
  modelSelect.addEventListener("change", () => { model = modelSelect.value; replan(); });
  text.addEventListener("input", () => { source = {pattern: text.value}; readText(); replan(250); });
  midi.addEventListener("change", () => midi.files[0] && loadMidi(midi.files[0]));
  table.addEventListener("dragover", (event) => event.preventDefault());
  table.addEventListener("drop", (event) => {
    event.preventDefault();
    const file = event.dataTransfer.files[0];
    if (file) loadMidi(file);
  });
  api("part_options").then((options) => {
    for (const name of options.strokes) penSelect.append(el("option", {value: name}, name));
    kitRows = options.kit_rows;
    kitSwitch.disabled = false;
  }).catch((error) => status(error.message, {error: true}));
  api("rudiments").then(({rudiments}) => {
    for (const r of rudiments) rudiment.append(el("option", {value: r.name}, `${r.number}. ${r.title}`));
  }).catch((error) => status(error.message, {error: true}));
  drawGrid();
  text.value = source.pattern || "";
  replan();
}

// A cell's look: what a drummer would write for it.
function cellText(note, row) {
  if (!note) return "·";
  const letter = kit || row === "auto" ? "•" : row === "right" ? "R" : "L";  // a kit's limbs are the planner's
  const word = note.stroke === "auto" ? "" : note.stroke === "buzz" ? "z" : "*";
  return note.level === "ghost" ? `(${letter}${word})` : `${letter}${note.level === "accent" ? ">" : ""}${word}`;
}

// Steps a beat of the meter's note value (6/8 counts eighths), or a quarter note's when a beat is no whole step.
function beatSteps() {
  const per = STEPS[grid.steps], unit = per * 4 / +grid.meter.split("/")[1];
  return Number.isInteger(unit) && unit >= 1 ? unit : per;
}

function drawGrid() {
  const beat = beatSteps(), inBar = Math.round(barBeats() * STEPS[grid.steps]), count = stepCount();
  const count1 = (s) => `${Math.floor(s / inBar) + 1}.${+((s % inBar) / beat + 1).toFixed(3)}`;  // bar.beat
  const head = Array.from({length: count}, (_, s) => el(
    "span", {class: `step${s % inBar === 0 ? " bar" : ""}`, role: "columnheader"}, s % beat === 0 ? count1(s) : ""));
  const rows = [el("div", {class: "gridrow head", role: "row"},
                   el("span", {class: "rowname", role: "columnheader"}, ""), ...head)];
  gridRows().forEach(([row, name], r) => {
    const cells = [el("span", {class: "rowname", role: "rowheader"}, name)];
    for (let step = 0; step < count; step++) {
      const note = grid.cells.get(cellKey(row, step));
      const look = (note ? ` on ${note.level}` : "") + (step % inBar === 0 ? " bar" : "") +
                   (step % beat === 0 ? " beat" : "");
      cells.push(el("button", {
        class: `cell${look}`, role: "gridcell", "data-row": row, "data-step": step,
        tabindex: r === 0 && step === 0 ? 0 : -1, title: note ? `${note.level}, ${note.stroke}` : "",
        "aria-label": `${name} at ${count1(step)}: ${note ? `${note.level} ${note.stroke}` : "off"}`,
        onclick: () => cycle(row, step), onkeydown: (event) => move(event, r, step),
      }, cellText(note, row)));
    }
    rows.push(el("div", {class: "gridrow", role: "row"}, ...cells));
  });
  view.table.replaceChildren(...rows);
  view.table.classList.toggle("kit", kit);
}

function cycle(row, step) {
  const key = cellKey(row, step), note = grid.cells.get(key);
  const next = CYCLE[(CYCLE.indexOf(note ? note.level : null) + 1) % CYCLE.length];
  if (next) grid.cells.set(key, {level: next, stroke: note ? note.stroke : kit ? "auto" : pen});  // a kit note: one hit
  else grid.cells.delete(key);
  edited();
  view.table.querySelector(`[data-row="${CSS.escape(row)}"][data-step="${step}"]`).focus();
}

function move(event, r, step) {
  const d = {ArrowRight: [0, 1], ArrowLeft: [0, -1], ArrowDown: [1, 0], ArrowUp: [-1, 0]}[event.key];
  if (!d) return;
  event.preventDefault();
  const shown = gridRows(), row = shown[Math.min(shown.length - 1, Math.max(0, r + d[0]))][0];
  const to = Math.min(stepCount() - 1, Math.max(0, step + d[1]));
  const next = view.table.querySelector(`[data-row="${CSS.escape(row)}"][data-step="${to}"]`);
  if (!next) return;
  view.table.querySelectorAll(".cell").forEach((cell) => { cell.tabIndex = -1; });  // one cell in the tab order
  next.tabIndex = 0;
  next.focus();
}

function trim() {  // notes past the grid's end are dropped with it
  for (const key of [...grid.cells.keys()]) if (keyParts(key)[1] >= stepCount()) grid.cells.delete(key);
}

function resample(steps) {  // the notes kept where the new steps hold them
  const from = STEPS[grid.steps], to = STEPS[steps], cells = new Map();
  for (const [key, note] of grid.cells) {
    const [row, step] = keyParts(key), k = (step / from) * to;
    if (Math.abs(k - Math.round(k)) < 1e-9) cells.set(cellKey(row, Math.round(k)), note);
  }
  grid.steps = steps;
  grid.cells = cells;
}

// The Kit switch: the grid shows the other mode's cells (the kit's groove the first time), and its text is the part.
function setKit(on) {
  if (on === kit) return;
  const shown = {cells: grid.cells, steps: grid.steps}, steps = grid.steps;
  kit = on;
  if (otherCells) {  // kept on the steps they were set on: brought to the grid's
    Object.assign(grid, otherCells);
    resample(steps);
  } else grid.cells = kitGroove();
  otherCells = shown;
  trim();
  view.penSelect.disabled = kit;  // on the kit a note is one hit: its limb and stroke are the planner's
  view.kitOptions.hidden = !kit;
  view.downloads.querySelector("#part-download-ros").hidden = kit;  // the robot's file: the sticks' part only
  view.downloads.querySelector("#part-download-plot").hidden = !kit;  // compose --kit --plot's picture
  view.table.classList.remove("stale");
  edited();
}

// The grid changed: its text is the part.
function edited() {
  drawGrid();
  source = {pattern: gridText()};
  view.text.value = source.pattern;
  view.fits.textContent = "";
  if (!grid.cells.size) {  // nothing to plan: said, not asked
    planned = null;
    view.lanes.replaceChildren();
    view.problems.replaceChildren();
    view.sticking.textContent = "";
    status("the grid is empty: click a cell to add a note");
    return;
  }
  replan(0);
}

// The text changed: the grid follows when the text fits it.
function readText() {
  const read = textGrid(view.text.value);
  if (!read) {
    view.fits.textContent = `The text does not fit the grid (${kit ? "steps, pieces, limbs, strokes" :
                            "steps, sticks"} or levels it has not): the text is what plays; a click on the grid ` +
                            "replaces it with the grid's notes.";
    view.table.classList.add("stale");
    return;
  }
  Object.assign(grid, read);
  for (const key of ["tempo", "meter", "bars", "steps"]) view[key].value = grid[key];
  view.table.classList.remove("stale");
  view.fits.textContent = "";
  drawGrid();
}

async function loadRudiment() {
  source = {rudiment: view.rudiment.value, tempo: +view.rudimentTempo.value, bars: grid.bars};
  await replan();
}

async function loadMidi(file) {
  if (file.size > 512 * 1024) { status(`${file.name} is ${file.size} bytes; at most 524288`, {error: true}); return; }
  const bytes = new Uint8Array(await file.arrayBuffer());
  let binary = "";
  for (let i = 0; i < bytes.length; i += 0x8000) binary += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  source = {midi: btoa(binary), name: file.name};
  await replan();
}

let timer = null, changedAt = 0;  // performance.now() of the last change: the time to its drawn lanes is the latency
function replan(delay = 0) {
  changedAt = performance.now();
  clearTimeout(timer);
  return new Promise((resolve) => {
    timer = setTimeout(() => queue(async () => { await planNow(); resolve(); }), delay);
  });
}

async function planNow() {
  const asked = source, started = performance.now();
  delete document.body.dataset.planned;
  try {
    const answer = await api("plan", currentPart());
    if (asked !== source) return;  // the part changed while it was planned: the next plan draws
    planned = {...answer, source: asked};
    if (!("pattern" in asked)) {  // a rudiment or a MIDI file: its text shown, the grid following if it fits
      view.text.value = answer.pattern;
      readText();
    }
    draw(answer);
    const played = answer.notes.filter((n) => n.played).length;
    status(`planned ${played} of ${answer.notes.length} notes in ${Math.round(performance.now() - started)} ms` +
           (answer.problems.length ? `; ${answer.problems.length} problem(s), below` : ""),
           {error: answer.problems.length > 0});
    document.body.dataset.planned = String(answer.notes.length);
    document.body.dataset.partLatency = (performance.now() - changedAt).toFixed(1);
  } catch (error) {
    status(error.message, {error: true});
    document.body.dataset.planned = "error";
  }
}

// Where a time (s, the score's) falls: "bar 2, beat 3.5" (beats of the meter's note value).
function where(t, answer) {
  const bars = answer.bars, [n] = answer.meter;
  if (bars.length < 2) return `${t.toFixed(3)} s`;
  let k = bars.findLastIndex((b) => b <= t + 1e-9);
  if (k < 0) return `before bar 1 (${(t - bars[0]).toFixed(3)} s)`;
  k = Math.min(k, bars.length - 2);
  const beat = 1 + (t - bars[k]) / (bars[k + 1] - bars[k]) * n;
  return `bar ${k + 1}, beat ${+beat.toFixed(2)}`;
}

// The sticks in a drummer's order (right, left, then any other by name), and each one's lane title.
export function stickOrder(sticks) {
  const rank = (name) => (name === "right" ? "0" : name === "left" ? "1" : `2${name}`);
  return Object.keys(sticks).sort((a, b) => (rank(a) < rank(b) ? -1 : 1));
}

export function stickLabel(name) {
  return name === "right" ? "R, the right stick" : name === "left" ? "L, the left stick" : name;
}

// A vertical line across chart c at time t.
export function across(c, t, cls) {
  return svgEl("line", {x1: c.x(t), x2: c.x(t), y1: c.margins.top, y2: c.height - c.margins.bottom, class: cls});
}

// The bar lines of chart c, labelled "bar 1", "bar 2", ..., and (beats > 1) the beats between them, dotted.
export function barLines(c, bars, beats = 1) {
  const g = c.layer("bars");
  bars.forEach((b, k) => {
    g.append(across(c, b, "barline"));
    if (k === bars.length - 1) return;
    for (let i = 1; i < beats; i++) g.append(across(c, b + (bars[k + 1] - b) * i / beats, "beatline"));
    const text = svgEl("text", {x: c.x(b) + 3, y: c.height - c.margins.bottom - 4, class: "barlabel"});
    text.textContent = `bar ${k + 1}`;
    g.append(text);
  });
}

function draw(answer) {
  if (answer.kit) { drawKit(answer); return; }
  const names = stickOrder(answer.sticks);
  const thetas = names.flatMap((name) => answer.sticks[name].theta);
  const low = Math.min(answer.head, ...thetas), high = Math.max(answer.head, ...thetas);
  const pad = 0.08 * (high - low || 1), yRange = [low - pad, high + 3 * pad];  // one scale for every stick
  const t0 = Math.min(0, ...names.map((n) => answer.sticks[n].t[0])), xRange = [t0, answer.t_end];
  const count = Math.max(1, answer.bars.length - 1), meter = answer.meter.join("/");
  const bars = `${count > 1 ? `bars 1–${count}` : "bar 1"} at ${+answer.tempo.toFixed(2)} bpm in ${meter}`;
  view.lanes.replaceChildren();
  const cursors = [];
  for (const name of names) {
    const lane = answer.sticks[name], box = el("div", {class: "lane", "data-stick": name});
    view.lanes.append(box);
    const c = chart(box, {width: 1300, height: 150, xRange, yRange, yLabel: "θ (rad)", xLabel: "time (s)",
                          title: `${stickLabel(name)}: ${bars}`});
    barLines(c, answer.bars, answer.meter[0]);
    c.line(xRange, [answer.head, answer.head], "head");
    c.line(lane.t, lane.theta, `theta stick-${name}`);
    c.dots(lane.impacts.t, lane.impacts.t.map(() => answer.head),
           lane.impacts.level_db.map((l) => Math.max(1.5, 3 + l / 4)), "impact");
    const marks = c.layer("marks");
    answer.notes.forEach((note, k) => {
      if (note.stick !== name) return;
      const t = note.impact ? note.impact.t : note.time;
      const text = svgEl("text", {x: c.x(t), y: c.y(yRange[1]) + 14, "text-anchor": "middle",
                                  class: `mark${note.played ? "" : " missed"}`, "data-note": k});
      text.textContent = note.mark;
      const tip = svgEl("title");
      tip.textContent = `${where(note.time, answer)}: ${note.mark}, velocity ${note.velocity}, ${note.stroke}` +
        (note.impact ? `; impact ${note.impact.level_db.toFixed(1)} dB` : "; not played");
      text.append(tip);
      marks.append(text);
    });
    problemMarks(c, marks, answer, (note) => note.stick === name, c.y(answer.head));
    cursors.push([c, c.layer("cursor")]);
  }
  view.cursors = cursors;
  view.sticking.textContent = `Sticking: ${answer.sticking}`;
  listProblems(answer);
}

const LIMBS = {right: "R, the right hand", left: "L, the left hand", "right-foot": "RF, the right foot",
               "left-foot": "LF, the left foot"};

// A kit part: a lane per piece (its hits at their level in dB, one scale for every piece and limb, coloured by the
// limb, an open hi-hat hollow; each note's mark above; the problems beside their notes), then every limb's θ.
function drawKit(answer) {
  const levels = Object.values(answer.lanes).flatMap((lane) => lane.level_db);
  const low = Math.min(-40, ...levels), high = Math.max(20, ...levels);
  const yRange = [low, high + 0.45 * (high - low)];  // room above the hits for the marks
  const xRange = [-answer.offset, answer.t_end];
  const count = Math.max(1, answer.bars.length - 1), meter = answer.meter.join("/");
  const bars = `${count > 1 ? `bars 1–${count}` : "bar 1"} at ${+answer.tempo.toFixed(2)} bpm in ${meter}`;
  view.lanes.replaceChildren();
  const cursors = [];
  for (const name of answer.pieces) {
    const lane = answer.lanes[name], box = el("div", {class: "lane kit-lane", "data-piece": name});
    view.lanes.append(box);
    const c = chart(box, {width: 1300, height: 116, xRange, yRange, yLabel: "dB", xLabel: "",
                          title: `${name}: ${bars}`});
    barLines(c, answer.bars, answer.meter[0]);
    const hits = c.layer("hits");
    lane.t.forEach((t, k) => {
      const limb = lane.limb[k], open = lane.state[k] === "open" || lane.state[k] === "half";
      const look = `hit limb-${limb}${open ? " open" : ""}${lane.note[k] < 0 ? " bounce" : ""}`;
      const dot = svgEl("circle", {cx: c.x(t), cy: c.y(lane.level_db[k]),
                                   r: Math.max(1.5, 3 + (lane.level_db[k] - low) / 10), class: look});
      const tip = svgEl("title");
      tip.textContent = `${where(t, answer)}: ${LIMBS[limb] || limb}, ${lane.level_db[k].toFixed(1)} dB` +
                        (lane.state[k] ? `, ${lane.state[k]}` : "") + (lane.note[k] < 0 ? " (a bounce)" : "");
      dot.append(tip);
      hits.append(dot);
    });
    const marks = c.layer("marks");
    answer.notes.forEach((note, k) => {
      if (note.piece !== name) return;
      const t = note.impact ? note.impact.t : note.time;
      const text = svgEl("text", {x: c.x(t), y: c.y(yRange[1]) + 14, "text-anchor": "middle",
                                  class: `mark${note.played ? "" : " missed"}`, "data-note": k});
      text.textContent = note.mark;
      const tip = svgEl("title");
      tip.textContent = `${where(note.time, answer)}: ${note.piece}${note.state ? ` ${note.state}` : ""}, ` +
        `${note.limb ? LIMBS[note.limb] || note.limb : "no limb"}, velocity ${note.velocity}` +
        (note.impact ? `; impact ${note.impact.level_db.toFixed(1)} dB` : "; not played");
      text.append(tip);
      marks.append(text);
    });
    problemMarks(c, marks, answer, (note) => note.piece === name, c.y(low));
    cursors.push([c, c.layer("cursor")]);
  }
  const limbs = Object.keys(answer.limbs), box = el("div", {class: "lane kit-limbs"});
  view.lanes.append(box);
  const thetas = limbs.flatMap((limb) => answer.limbs[limb].joints.theta);
  const c = chart(box, {width: 1300, height: 170, xRange,
                        yRange: [Math.min(...thetas) - 0.05, Math.max(...thetas) + 0.05], yLabel: "θ (rad)",
                        xLabel: "time (s)",
                        title: "each limb's θ: the sticks' angle to the horizontal, the beaters' back from the " +
                               "vertical (one scale)"});
  barLines(c, answer.bars, answer.meter[0]);
  limbs.forEach((limb, k) => {
    c.line(answer.limbs[limb].t, answer.limbs[limb].joints.theta, `theta limb-${limb}`);
    const key = svgEl("text", {x: c.width - c.margins.right - 4, y: c.margins.top + 12 + 13 * k,
                               "text-anchor": "end", class: `limbkey limb-${limb}`});
    key.textContent = LIMBS[limb] || limb;
    c.svg.append(key);
  });
  cursors.push([c, c.layer("cursor")]);
  view.cursors = cursors;
  const counts = limbs.map((limb) => {
    const notes = answer.notes.filter((n) => n.limb === limb && n.played);
    const pieces = [...new Set(notes.map((n) => n.piece))].join(", ");
    return notes.length ? `${(LIMBS[limb] || limb).split(",")[0]} ×${notes.length} (${pieces})` : "";
  }).filter(Boolean);
  view.sticking.textContent = `Limbs: ${counts.join(" · ")}`;
  listProblems(answer);
  markCells(answer);
}

// Each kit cell of a planned note written as the planner plays it: its limb with its accent or ghost (R>, (L), RF),
// when the grid is what was planned (its text is the part).
function markCells(answer) {
  if (view.table.classList.contains("stale")) return;
  const per = STEPS[grid.steps];
  for (const note of answer.notes) {
    const step = Math.round(note.beat * per);
    const row = kitRows.find((r) => r.piece === note.piece && (r.state === note.state || r.state === null));
    if (!row || note.beat === null || Math.abs(note.beat * per - step) > 1e-6) continue;
    const cell = view.table.querySelector(`[data-row="${CSS.escape(row.name)}"][data-step="${step}"]`);
    if (cell && cell.classList.contains("on")) {
      cell.textContent = note.mark.replace(/ .*/, "");  // the hi-hat's state is its row
      cell.title = `${note.piece}${note.state ? ` ${note.state}` : ""}: ${note.mark}` +
                   (note.played ? "" : ", not played");
      cell.classList.toggle("missed", !note.played);
    }
  }
}

// The problems of the notes of a lane (belongs(note)) drawn beside them in chart c's layer marks: a line down to
// the lane's baseline (y) and the reason, in rows so that near ones do not overlap.
function problemMarks(c, marks, answer, belongs, y0) {
  let shown = 0;
  answer.problems.forEach((problem, k) => {
    const note = answer.notes[problem.note];
    if (!note || !belongs(note)) return;
    const x = c.x(note.time), y = y0 - 6 - 13 * (shown++ % 4), left = x > 0.6 * c.width;
    const gp = svgEl("g", {class: "problem-mark", "data-note": problem.note, "data-problem": k});
    gp.append(svgEl("line", {x1: x, x2: x, y1: c.margins.top + 18, y2: y0, class: "problemline"}));
    const text = svgEl("text", {x: left ? x - 4 : x + 4, y, "text-anchor": left ? "end" : "start",
                                class: "problemtext"});
    text.textContent = `✕ ${note.mark} ${shortReason(problem.reason, note)}`;
    const tip = svgEl("title");
    tip.textContent = problem.reason;
    text.append(tip);
    gp.append(text);
    marks.append(gp);
  });
}

// The problems listed in time order, each with where its note is and the nearest playable time and level.
function listProblems(answer) {
  const time = (problem) => (problem.note === null ? Infinity : answer.notes[problem.note].time);
  const order = answer.problems.map((problem, k) => [problem, k]).sort(([a], [b]) => time(a) - time(b));
  view.problems.replaceChildren(...order.map(([problem, k]) => {
    const note = answer.notes[problem.note];
    const near = [problem.nearest_time !== null ? `nearest playable time ${where(problem.nearest_time, answer)} ` +
                  `(${problem.nearest_time.toFixed(4)} s)` : "",
                  problem.nearest_level !== null ? `nearest playable level ${problem.nearest_level.toFixed(2)} dB` : ""]
      .filter(Boolean).join("; ");
    const what = note && note.piece ? `${note.piece} ${note.mark}` : note && note.mark;  // a kit's note: its piece
    return el("li", {class: "problem", "data-note": problem.note ?? "", "data-problem": k},
              note ? el("strong", {}, `${where(note.time, answer)}, ${what}: `) : "",
              problem.reason, near ? ` — ${near}` : "");
  }));
}

function shortReason(reason, note) {  // the reason without its note's name (drawn beside the note already)
  const text = reason.startsWith(`${note.source}: `) ? reason.slice(note.source.length + 2) : reason;
  return text.length > 90 ? `${text.slice(0, 88)}…` : text;
}

function cursorAt(t) {
  for (const [c, layer] of view.cursors || []) {
    layer.replaceChildren();
    if (t !== null) layer.append(across(c, t, "cursor"));
  }
}

async function hear() {
  try {
    if (!planned || planned.source !== source) await planNow();  // the cursor needs this part's offset
    if (!planned || planned.source !== source) return;  // it could not be planned: the status line says why
    const file = await api("audio", currentPart());
    const offset = planned.offset;
    await play(file.blob, {onTime: (t) => cursorAt(t === null ? null : t - offset)});
    status("playing the part");
  } catch (error) {
    status(error.message, {error: true});
  }
}

async function take(kind) {
  try {
    const file = await api("download", {...currentPart(), kind});
    download(file);
    status(`downloaded ${file.filename}`);
  } catch (error) {
    status(error.message, {error: true});
  }
}
