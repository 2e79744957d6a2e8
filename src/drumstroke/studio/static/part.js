// The part editor: a step grid and its text pattern, kept in sync; the planner's part drawn as a drummer reads it
// (a lane per stick on one angle scale, the sticking, the problems next to their notes); heard with a cursor;
// the files 'drumstroke compose' writes. The part is always the text: the grid writes it, and reads it back when
// it fits the grid. The robot view plays the same part (currentPart()).
import {api, chart, download, el, latest, play, status, stop, svgEl} from "./common.js";

const ROWS = [["right", "R"], ["left", "L"], ["auto", "auto"]];
const LEVELS = {normal: 100, accent: 116, ghost: 45};  // MIDI velocities: R, R> and (R) as the sticking writes them
const CYCLE = [null, "normal", "accent", "ghost"];
const STEPS = {"16ths": 4, "8ths": 2, "triplets": 3};  // steps a quarter note
const METERS = ["4/4", "3/4", "2/4", "5/4", "6/8", "7/8", "12/8"];

const grid = {tempo: 100, meter: "4/4", bars: 2, steps: "16ths", cells: new Map()};  // cells: "row:step" -> note
let source = {pattern: ""};  // what plays: {pattern}, {midi, name} or {rudiment, tempo, bars}
let planned = null, model = "paper", pen = "auto";
const queue = latest();
let view = null;  // the DOM of the view once built

// The part the robot view and the requests use: the source and the model.
export function currentPart() {
  return {...source, model};
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
    for (const [row] of ROWS) {
      const note = grid.cells.get(`${row}:${step}`);
      if (note) lines.push(`${step / per} ${note.stroke} ${LEVELS[note.level]} ${row}`);
    }
  }
  return lines.join("\n") + "\n";
}

// The text read back into the grid when every note fits it (a step of the grid's, a stick of its rows, a level of
// its three, no buzz length, no kit piece, at most 8 bars); else null: the text is what plays.
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
      const [beat, stroke, velocity, stick = "right", ...rest] = f;
      const level = Object.keys(LEVELS).find((k) => LEVELS[k] === +velocity);
      if (rest.length || !level || !ROWS.some(([row]) => row === stick) || !(+beat >= 0)) return null;
      notes.push({beat: +beat, stroke, level, stick});
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
    const key = `${note.stick}:${Math.round(note.beat * STEPS[steps])}`;
    if (cells.has(key)) return null;
    cells.set(key, {level: note.level, stroke: note.stroke});
  }
  return {tempo, meter, bars: Math.max(bars, grid.bars), steps, cells};
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
                           ["pattern", "pattern"]].map(([kind, label]) =>
                         el("button", {id: `part-download-${kind}`, onclick: () => take(kind)}, label)));
  view = {tempo, meter, bars, steps, text, fits, table, lanes, problems, sticking, rudiment, rudimentTempo};
  section.append(
    el("h2", {}, "Part editor"),
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
  const letter = row === "auto" ? "•" : row === "right" ? "R" : "L";
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
  ROWS.forEach(([row, name], r) => {
    const cells = [el("span", {class: "rowname", role: "rowheader"}, name)];
    for (let step = 0; step < count; step++) {
      const note = grid.cells.get(`${row}:${step}`);
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
}

function cycle(row, step) {
  const key = `${row}:${step}`, note = grid.cells.get(key);
  const next = CYCLE[(CYCLE.indexOf(note ? note.level : null) + 1) % CYCLE.length];
  if (next) grid.cells.set(key, {level: next, stroke: note ? note.stroke : pen});
  else grid.cells.delete(key);
  edited();
  view.table.querySelector(`[data-row="${row}"][data-step="${step}"]`).focus();
}

function move(event, r, step) {
  const d = {ArrowRight: [0, 1], ArrowLeft: [0, -1], ArrowDown: [1, 0], ArrowUp: [-1, 0]}[event.key];
  if (!d) return;
  event.preventDefault();
  const row = ROWS[Math.min(ROWS.length - 1, Math.max(0, r + d[0]))][0];
  const to = Math.min(stepCount() - 1, Math.max(0, step + d[1]));
  const next = view.table.querySelector(`[data-row="${row}"][data-step="${to}"]`);
  if (!next) return;
  view.table.querySelectorAll(".cell").forEach((cell) => { cell.tabIndex = -1; });  // one cell in the tab order
  next.tabIndex = 0;
  next.focus();
}

function trim() {  // notes past the grid's end are dropped with it
  for (const key of [...grid.cells.keys()]) if (+key.split(":")[1] >= stepCount()) grid.cells.delete(key);
}

function resample(steps) {  // the notes kept where the new steps hold them
  const from = STEPS[grid.steps], to = STEPS[steps], cells = new Map();
  for (const [key, note] of grid.cells) {
    const [row, step] = key.split(":"), k = (+step / from) * to;
    if (Math.abs(k - Math.round(k)) < 1e-9) cells.set(`${row}:${Math.round(k)}`, note);
  }
  grid.steps = steps;
  grid.cells = cells;
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
    view.fits.textContent = "The text does not fit the grid (steps, sticks or levels it has not): the text is " +
                            "what plays; a click on the grid replaces it with the grid's notes.";
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
    let shown = 0;  // the problems of a lane in rows, so that near ones do not overlap
    answer.problems.forEach((problem, k) => {
      const note = answer.notes[problem.note];
      if (!note || note.stick !== name) return;
      const x = c.x(note.time), y = c.y(answer.head) - 6 - 13 * (shown++ % 4), left = x > 0.6 * c.width;
      const gp = svgEl("g", {class: "problem-mark", "data-note": problem.note, "data-problem": k});
      gp.append(svgEl("line", {x1: x, x2: x, y1: c.margins.top + 18, y2: c.y(answer.head), class: "problemline"}));
      const text = svgEl("text", {x: left ? x - 4 : x + 4, y, "text-anchor": left ? "end" : "start",
                                  class: "problemtext"});
      text.textContent = `✕ ${note.mark} ${shortReason(problem.reason, note)}`;
      const tip = svgEl("title");
      tip.textContent = problem.reason;
      text.append(tip);
      gp.append(text);
      marks.append(gp);
    });
    cursors.push([c, c.layer("cursor")]);
  }
  view.cursors = cursors;
  view.sticking.textContent = `Sticking: ${answer.sticking}`;
  const time = (problem) => (problem.note === null ? Infinity : answer.notes[problem.note].time);
  const order = answer.problems.map((problem, k) => [problem, k]).sort(([a], [b]) => time(a) - time(b));
  view.problems.replaceChildren(...order.map(([problem, k]) => {
    const note = answer.notes[problem.note];
    const near = [problem.nearest_time !== null ? `nearest playable time ${where(problem.nearest_time, answer)} ` +
                  `(${problem.nearest_time.toFixed(4)} s)` : "",
                  problem.nearest_level !== null ? `nearest playable level ${problem.nearest_level.toFixed(2)} dB` : ""]
      .filter(Boolean).join("; ");
    return el("li", {class: "problem", "data-note": problem.note ?? "", "data-problem": k},
              note ? el("strong", {}, `${where(note.time, answer)}, ${note.mark}: `) : "",
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
