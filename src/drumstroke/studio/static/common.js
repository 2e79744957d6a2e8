// What every view of the studio shares: asking the server, the status line, SVG charts and playing audio.

const SVG = "http://www.w3.org/2000/svg";

// Ask the server for an operation: POST /api/NAME with a JSON object. Resolves to the answer's JSON, or to a
// {blob, filename} for a file; rejects with an Error whose message is the server's one-line reason.
// A request the studio is too busy for (503 with Retry-After: two run at once) is asked again, up to 3 times.
export async function api(name, body = {}) {
  let response;
  for (let attempt = 1; ; attempt++) {
    response = await fetch(`/api/${name}`, {
      method: "POST", headers: {"Content-Type": "application/json"}, body: JSON.stringify(body),
    });
    if (response.status !== 503 || !response.headers.get("Retry-After") || attempt > 3) break;
    await new Promise((resolve) => setTimeout(resolve, 300 * attempt));
  }
  const type = response.headers.get("Content-Type") || "";
  if (!response.ok) {
    let reason = `${response.status} ${response.statusText}`;
    if (type.startsWith("application/json")) reason = (await response.json()).error || reason;
    throw new Error(reason);
  }
  if (type.startsWith("application/json")) return response.json();
  const match = /filename="([^"]+)"/.exec(response.headers.get("Content-Disposition") || "");
  return {blob: await response.blob(), filename: match ? match[1] : name};
}

// Say something on the status line (an error in its colour).
export function status(text, {error = false} = {}) {
  const line = document.getElementById("status");
  line.textContent = text;
  line.classList.toggle("error", error);
}

// An element: el("button", {id: "x", onclick: f}, "text", child, ...).
export function el(tag, attributes = {}, ...children) {
  const node = document.createElement(tag);
  for (const [key, value] of Object.entries(attributes)) {
    if (key.startsWith("on")) node.addEventListener(key.slice(2), value);
    else if (value !== false && value !== null && value !== undefined) node.setAttribute(key, value === true ? "" : value);
  }
  for (const child of children) node.append(child);
  return node;
}

export function svgEl(tag, attributes = {}) {
  const node = document.createElementNS(SVG, tag);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, value);
  return node;
}

// Save a {blob, filename} (an api() file) as a download.
export function download({blob, filename}) {
  const link = el("a", {href: URL.createObjectURL(blob), download: filename});
  document.body.append(link);
  link.click();
  link.remove();
  setTimeout(() => URL.revokeObjectURL(link.href), 10000);
}

// A chart: an SVG of width x height user units with margins, axes from xRange and yRange, and its scales.
// chart.x(v), chart.y(v): data to SVG; chart.fromX(px), chart.fromY(py): back; chart.line(xs, ys, cls);
// chart.dots(xs, ys, radii, cls); chart.band(x0, x1, cls); chart.layer(): a <g> to draw into.
export function chart(container, {width = 1000, height = 300, xRange, yRange, xLabel = "", yLabel = "",
                                  title = ""}) {
  const m = {left: 56, right: 12, top: title ? 22 : 10, bottom: 34};
  const svg = svgEl("svg", {viewBox: `0 0 ${width} ${height}`, class: "chart", role: "img",
                            "aria-label": title || yLabel});
  const [x0, x1] = xRange, [y0, y1] = yRange;
  const sx = (width - m.left - m.right) / ((x1 - x0) || 1), sy = (height - m.top - m.bottom) / ((y1 - y0) || 1);
  const c = {
    svg, width, height, margins: m,
    x: (v) => m.left + (v - x0) * sx,
    y: (v) => height - m.bottom - (v - y0) * sy,
    fromX: (px) => x0 + (px - m.left) / sx,
    fromY: (py) => y0 + (height - m.bottom - py) / sy,
    layer(cls = "") { const g = svgEl("g", {class: cls}); svg.append(g); return g; },
    line(xs, ys, cls, into = svg) {
      let d = "";
      for (let i = 0; i < xs.length; i++) d += `${i ? "L" : "M"}${c.x(xs[i]).toFixed(2)},${c.y(ys[i]).toFixed(2)}`;
      const path = svgEl("path", {d, class: cls});
      into.append(path);
      return path;
    },
    dots(xs, ys, radii, cls, into = svg) {
      const g = svgEl("g", {class: cls});
      xs.forEach((x, i) => g.append(svgEl("circle", {cx: c.x(x), cy: c.y(ys[i]), r: radii[i] ?? radii})));
      into.append(g);
      return g;
    },
    band(a, b, cls, into = svg) {
      const rect = svgEl("rect", {x: c.x(a), y: m.top, width: Math.max(0, c.x(b) - c.x(a)),
                                  height: height - m.top - m.bottom, class: cls});
      into.append(rect);
      return rect;
    },
  };
  const axes = svgEl("g");
  for (const v of ticks(x0, x1, 10)) {
    axes.append(svgEl("line", {x1: c.x(v), x2: c.x(v), y1: m.top, y2: height - m.bottom, class: "grid"}));
    const label = svgEl("text", {x: c.x(v), y: height - m.bottom + 14, "text-anchor": "middle"});
    label.textContent = fmt(v);
    axes.append(label);
  }
  for (const v of ticks(y0, y1, 5)) {
    axes.append(svgEl("line", {x1: m.left, x2: width - m.right, y1: c.y(v), y2: c.y(v), class: "grid"}));
    const label = svgEl("text", {x: m.left - 4, y: c.y(v) + 4, "text-anchor": "end"});
    label.textContent = fmt(v);
    axes.append(label);
  }
  axes.append(svgEl("rect", {x: m.left, y: m.top, width: width - m.left - m.right,
                             height: height - m.top - m.bottom, class: "axis"}));
  for (const [text, attrs] of [[xLabel, {x: (m.left + width - m.right) / 2, y: height - 4, "text-anchor": "middle"}],
                               [yLabel, {x: 12, y: (m.top + height - m.bottom) / 2, "text-anchor": "middle",
                                         transform: `rotate(-90 12 ${(m.top + height - m.bottom) / 2})`}],
                               [title, {x: m.left, y: 14}]]) {
    if (!text) continue;
    const label = svgEl("text", attrs);
    label.textContent = text;
    axes.append(label);
  }
  svg.append(axes);
  container.replaceChildren(svg);
  return c;
}

// Round tick values between a and b, about n of them.
export function ticks(a, b, n) {
  if (!(b > a)) return [a];
  const raw = (b - a) / n, power = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 5, 10].map((k) => k * power).find((s) => s >= raw);
  const out = [];
  for (let v = Math.ceil(a / step) * step; v <= b + step * 1e-9; v += step) out.push(Math.abs(v) < step * 1e-9 ? 0 : v);
  return out;
}

export function fmt(v) {
  return Math.abs(v) >= 1000 || (Math.abs(v) < 0.01 && v !== 0) ? v.toExponential(1) : String(+v.toFixed(3));
}

// Audio: one context for the page; play() decodes a WAV (a Blob or ArrayBuffer) and plays it, calling
// onTime(seconds) every frame until it ends (a cursor follows it); stop() ends what plays.
let context = null, playing = null;

export async function play(wav, {onTime = null} = {}) {
  stop();
  context = context || new AudioContext();
  if (context.state === "suspended") await context.resume();
  const data = wav instanceof Blob ? await wav.arrayBuffer() : wav;
  const buffer = await context.decodeAudioData(data);
  const source = context.createBufferSource();
  source.buffer = buffer;
  source.connect(context.destination);
  const started = context.currentTime;
  const state = {source, done: false, duration: buffer.duration};
  playing = state;
  source.onended = () => { state.done = true; if (onTime) onTime(null); document.body.dataset.played = "yes"; };
  source.start();
  document.body.dataset.playing = "yes";
  const frame = () => {
    if (state.done) { delete document.body.dataset.playing; return; }
    if (onTime) onTime(context.currentTime - started);
    requestAnimationFrame(frame);
  };
  requestAnimationFrame(frame);
  return state;
}

export function stop() {
  if (playing && !playing.done) { playing.source.stop(); playing.done = true; }
  playing = null;
}

// Whole requests in order: run(f) starts f() when none is running, else keeps only the latest f until then
// (a drag asks for many strokes; only the last asked matters).
export function latest() {
  let running = false, next = null;
  const run = async (f) => {
    if (running) { next = f; return; }
    running = true;
    try { await f(); } finally {
      running = false;
      if (next) { const g = next; next = null; run(g); }
    }
  };
  return run;
}
