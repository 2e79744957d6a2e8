"""Time the studio as a person uses it, in Debian's Chromium: ``python benchmarks/studio.py [--moves 40]``.

Cases (each from a real event in the page to the picture redrawn, as the page measures it with
``performance.now()``; Playwright drives the mouse):

- **a drag to a redrawn stroke**: a breakpoint of ``low-high``'s force dragged ``--moves`` small steps with the
  mouse; each step simulated again by the server and drawn (θ(t), impacts, rests), the time from the handle's
  move to the drawing done (``data-designer-latency``). Target: under 50 ms (issue 31).
- **a grid edit to a planned part**: a 2-bar groove of 8th notes on two sticks (16 notes) built by clicks on the
  step grid, each click planned by the server and drawn (a lane per stick, the sticking, the problems), from the
  click's handler to the lanes drawn (``data-part-latency``). Target: under 200 ms.

Reference, in the same process: what the same change cost before the studio, the command line a person ran
and the picture they opened: ``drumstroke simulate RECIPE.toml --plot stroke.png`` and ``drumstroke compose
groove.pattern --plot part.png`` (each the least of 3 runs, in a process of its own, as typed in a shell).

Prints a table and writes it with the machine and date to benchmarks/studio_results.json.
"""

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from playwright.sync_api import sync_playwright

from _timing import machine, progress
from drumstroke.presets import preset
from drumstroke.studio.app import make_studio

HERE = Path(__file__).resolve().parent
CHROMIUM = "/usr/bin/chromium"


def stroke_latencies(page, moves):
    """The page's drag-to-drawn times (ms) of ``moves`` mouse steps of one breakpoint."""
    page.wait_for_selector("body[data-designer-state=drawn]", timeout=60000)
    handle = page.locator('#designer-force circle.handle[data-point="2"]')
    box = handle.bounding_box()
    x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    page.mouse.move(x, y)
    page.mouse.down()
    times = []
    for k in range(1, moves + 1):
        page.evaluate("delete document.body.dataset.designerLatency")
        page.mouse.move(x - 3 * k, y + (4 if k % 2 else -4))  # earlier, up and down: each move a new stroke
        page.wait_for_selector("body[data-designer-latency][data-designer-state=drawn]", state="attached",
                               timeout=60000)
        times.append(float(page.evaluate("document.body.dataset.designerLatency")))
    page.mouse.up()
    return times


def part_latencies(page):
    """The page's click-to-lanes times (ms) of the 16 clicks that build a 2-bar groove of 8th notes."""
    page.click("#tab-part")
    page.wait_for_selector("body[data-planned]", timeout=60000)
    page.click("#part-clear")
    times = []
    for k in range(16):
        cell = f".cell[data-row='{'right' if k % 2 == 0 else 'left'}'][data-step='{2 * k}']"
        page.evaluate("delete document.body.dataset.partLatency")
        page.click(cell)
        page.wait_for_selector(f"body[data-planned='{k + 1}'][data-part-latency]", state="attached", timeout=60000)
        times.append(float(page.evaluate("document.body.dataset.partLatency")))
    return times, page.input_value("#part-text")


def command_line(argv):
    """The least wall time (ms) of 3 runs of ``drumstroke ARGV`` in a process of its own."""
    best = float("inf")
    for _ in range(3):
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "drumstroke", *argv], check=True, capture_output=True)
        best = min(best, time.perf_counter() - start)
    return 1e3 * best


def summary(times):
    ordered = sorted(times)
    return {"median_ms": statistics.median(ordered), "p90_ms": ordered[int(0.9 * (len(ordered) - 1))],
            "max_ms": ordered[-1], "n": len(ordered)}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--moves", type=int, default=40, help="mouse steps of the drag (default 40)")
    args = parser.parse_args()
    server = make_studio(port=0).start()
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=CHROMIUM, headless=True, args=["--no-sandbox"])
            page = browser.new_page(viewport={"width": 1366, "height": 768})
            page.goto(server.url)
            progress(f"dragging a breakpoint {args.moves} steps")
            stroke = stroke_latencies(page, args.moves)
            progress("building a 2-bar groove on the grid")
            part, groove = part_latencies(page)
            browser.close()
    finally:
        server.stop()
    with tempfile.TemporaryDirectory() as folder:
        recipe, pattern = Path(folder) / "low-high.toml", Path(folder) / "groove.pattern"
        preset("low-high").to_toml(recipe)
        pattern.write_text(groove)
        progress("the command line, for reference")
        stroke_cli = command_line(["simulate", str(recipe), "--plot", str(Path(folder) / "stroke.png")])
        part_cli = command_line(["compose", str(pattern), "--quiet", "--plot", str(Path(folder) / "part.png")])
    rows = [("a drag to a redrawn stroke (low-high)", summary(stroke), stroke_cli, 50.0),
            ("a grid edit to a planned 2-bar part", summary(part), part_cli, 200.0)]
    print(f"{'case':<42}{'median':>10}{'p90':>10}{'max':>10}{'command line':>15}{'ratio':>8}  target")
    for name, s, cli, target in rows:
        print(f"{name:<42}{s['median_ms']:>8.1f}ms{s['p90_ms']:>8.1f}ms{s['max_ms']:>8.1f}ms{cli:>13.0f}ms"
              f"{cli / s['median_ms']:>7.0f}x  < {target:g} ms: {'met' if s['max_ms'] < target else 'not met'}")
    results = {"machine": machine(),
               "cases": [{"case": name, **s, "command_line_ms": cli, "target_ms": target}
                         for name, s, cli, target in rows]}
    (HERE / "studio_results.json").write_text(json.dumps(results, indent=1) + "\n")


if __name__ == "__main__":
    main()
