#!/usr/bin/env python3
"""The flight report opens in headless Chromium, its 3D view, its plots and its 2D top view
draw, and its playback slider puts the vehicle where the log has it.

cites: REQ-REPORT-003
cites: REQ-REPORT-009
cites: REQ-REPORT-010
cites: REQ-REPORT-011
cites: REQ-REPORT-012
cites: REQ-REPORT-013

usage: check_report.py MINER_BINARY WORK_DIR

Runs `miner fly --out WORK_DIR/run`, then loads WORK_DIR/run/report.html#t=T (T: half the
flight, so the playback marker is mid-way) in headless Chromium twice, each time dumping
the DOM after the scripts ran and taking a screenshot (decoded here: PNG, zlib only):
  1. with software WebGL (SwiftShader): the viewer's #miner-status says "drawn", view
     "3d", more than 1 % of the view's pixels drawn; the screenshot's view area (where the
     viewer says it is) holds more than 1 % drawn pixels and more than 16 colours; the
     flown path has more than one error colour; the marker is the log's truth at T;
  2. with WebGL disabled (--disable-gpu --disable-webgl --disable-3d-apis), in a window as
     tall as the page's plots (where the first run's viewer says they end): the viewer falls back to the
     top view (view "top") and says "drawn", the screenshot's view area is drawn as above,
     and each plot (per-axis position, velocity, attitude, EKF error, rotors, the event
     timeline, ...) holds data lines: coloured pixels inside its rectangle.
The screenshots stay in WORK_DIR (report-3d.png, report-top.png).
"""
import html
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import zlib

VIEW_W, VIEW_H = 1200, 640          # #view3d in the report's style sheet
VIEW_BACKGROUND = (247, 247, 247)   # the renderer's clear colour, 0xf7f7f7
MIN_DRAWN_FRACTION = 0.01
MIN_COLOURS = 16


def chromium_binary():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    sys.exit("check_report: no chromium found (ci/setup.sh installs Debian's chromium)")


def chromium(args, profile):
    cmd = [chromium_binary(), "--headless", "--no-sandbox", "--disable-dev-shm-usage",
           "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--hide-scrollbars",
           "--user-data-dir=" + profile, "--virtual-time-budget=5000",
           "--enable-logging=stderr", "--v=0"] + args
    return subprocess.run(cmd, capture_output=True, text=True, timeout=240)


def decode_png(data, max_rows=None):
    """RGB(A) 8-bit non-interlaced PNG -> (width, height, channels, rows of bytes); only the
    first max_rows rows are unfiltered when given (the rest are not needed)."""
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG")
    pos, idat, width = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or colour not in (2, 6) or interlace:
                raise ValueError(f"unsupported PNG (depth {depth}, colour type {colour}, interlace {interlace})")
            channels = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = width * channels
    # Byte-wise addition modulo 256 of whole rows at once (filter "up"), on big integers.
    high = int.from_bytes(b"\x80" * stride, "big")
    low = high ^ int.from_bytes(b"\xff" * stride, "big")
    rows, prev = [], bytes(stride)
    for y in range(height if max_rows is None else min(height, max_rows)):
        f = raw[y * (stride + 1)]
        line = raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)]
        if f == 2:
            a, b = int.from_bytes(line, "big"), int.from_bytes(prev, "big")
            line = (((a & low) + (b & low)) ^ ((a ^ b) & high)).to_bytes(stride, "big")
        elif f != 0:
            line = bytearray(line)
            for i in range(stride):
                a = line[i - channels] if i >= channels else 0
                b = prev[i]
                c = prev[i - channels] if i >= channels else 0
                if f == 1:
                    line[i] = (line[i] + a) & 255
                elif f == 3:
                    line[i] = (line[i] + (a + b) // 2) & 255
                elif f == 4:
                    p = a + b - c
                    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                    line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
            line = bytes(line)
        rows.append(line)
        prev = line
    return width, height, channels, rows


def status_of(dom):
    """The data-* attributes of #miner-status in a dumped DOM, or None."""
    m = re.search(r'<p id="miner-status"([^>]*)>', dom)
    if not m:
        return None
    return {k: html.unescape(v) for k, v in re.findall(r'data-([a-z-]+)="([^"]*)"', m.group(1))}


def area_stats(png, box):
    """Drawn pixels (not the view's background nor white), colours and coloured (saturated)
    pixels of a rectangle x,y,w,h of a decoded screenshot."""
    w, h, ch, rows = png
    x0, y0, bw, bh = box
    drawn = coloured = total = 0
    colours = set()
    for y in range(max(0, y0), min(h, len(rows), y0 + bh)):
        row = rows[y]
        for x in range(max(0, x0), min(w, x0 + bw)):
            px = row[x * ch:x * ch + 3]
            total += 1
            colours.add(px)
            r, g, b = px[0], px[1], px[2]
            if abs(r - VIEW_BACKGROUND[0]) + abs(g - VIEW_BACKGROUND[1]) + abs(b - VIEW_BACKGROUND[2]) > 24 and \
                    r + g + b < 3 * 250:
                drawn += 1
            if max(r, g, b) - min(r, g, b) > 60:
                coloured += 1
    return drawn, total, len(colours), coloured


def read_log(path):
    """flight_log.csv as {column: [values]}; a header "true_x [m]" or "true_x (m)" names true_x."""
    with open(path) as f:
        header = [re.split(r"[\s\[(]", c.strip(), maxsplit=1)[0] for c in f.readline().split(",")]
        cols = {c: [] for c in header}
        for line in f:
            for c, v in zip(header, line.split(",")):
                cols[c].append(float(v))
    return cols


PLOTS = ["plot-events", "plot-position-x", "plot-position-y", "plot-position-z", "plot-velocity-x",
         "plot-velocity-y", "plot-velocity-z", "plot-attitude-roll", "plot-attitude-pitch", "plot-attitude-yaw",
         "plot-ekf-x", "plot-ekf-y", "plot-ekf-z", "plot-rotors", "plot-thrust", "plot-error", "plot-tracking-axes", "plot-speed"]
LAYERS = ["grid and axes", "map", "trajectory", "planned path", "repaired path", "flown", "start / goal", "vehicle"]
MIN_COLOURED = 150     # coloured pixels of a plot's data lines (its frame, grid and text are grey)
PAGE_HEIGHT = 3600     # the second run's window when the first run did not say where the plots are


def check_view(name, dom, st, png, failures, want_view, t, log):
    if st is None:
        failures.append(f"{name}: no #miner-status in the dumped DOM (did the page load?)")
        return
    if "Grid: <b>" not in dom:
        failures.append(f"{name}: the view does not say the grid's spacing")
    state, pixels = st.get("state", "?"), int(st.get("pixels", "0") or 0)
    print(f"{name}: viewer state {state}, view {st.get('view')}, {pixels} drawn pixels of {VIEW_W * VIEW_H}, "
          f"t = {st.get('t')} s, marker ({st.get('marker')}) at log time {st.get('marker-t')}, "
          f"{st.get('flown-colours')} flown-path colours")
    if state != "drawn":
        failures.append(f"{name}: the viewer reports '{state}'")
        return
    if st.get("view") != want_view:
        failures.append(f"{name}: the viewer drew the '{st.get('view')}' view, not '{want_view}'")
    if pixels < MIN_DRAWN_FRACTION * VIEW_W * VIEW_H:
        failures.append(f"{name}: only {pixels} pixels drawn")
    if int(st.get("flown-colours", "0")) < 2:
        failures.append(f"{name}: the flown path is not coloured by tracking error")
    layers = st.get("layers", "").split(",")
    for layer in LAYERS:
        if layer not in layers:
            failures.append(f"{name}: no '{layer}' layer toggle")
    if st.get("not-depth-tested") != "0":
        failures.append(f"{name}: {st.get('not-depth-tested')} objects are drawn without the depth test")
    if not float(st.get("grid-step", "0")) > 0:
        failures.append(f"{name}: no ground grid")
    # The playback marker: at the slider's time, where the log has the vehicle.
    if abs(float(st.get("t", "nan")) - t) > 1e-6:
        failures.append(f"{name}: the playback time is {st.get('t')}, not {t:.2f}")
    try:
        mt = float(st["marker-t"])
        marker = [float(v) for v in st["marker"].split(",")]
        k = min(range(len(log["t"])), key=lambda i: abs(log["t"][i] - mt))
        truth = [log["true_x"][k], log["true_y"][k], log["true_z"][k]]
        if not (0 <= t - mt <= 0.05 + 1e-6) or abs(log["t"][k] - mt) > 1e-3 or \
                max(abs(a - b) for a, b in zip(marker, truth)) > 2e-3:
            failures.append(f"{name}: the marker {marker} at {mt} s is not the log's {truth} at {log['t'][k]} s")
    except (KeyError, ValueError) as e:
        failures.append(f"{name}: no playback marker ({e})")
    box = [int(v) for v in st.get("view-rect", "0,0,0,0").split(",")]
    drawn, total, colours, _ = area_stats(png, box)
    print(f"{name} screenshot: view {box[2]}x{box[3]} px at ({box[0]},{box[1]}), "
          f"{100.0 * drawn / max(total, 1):.1f} % drawn, {colours} colours")
    if total < 0.9 * VIEW_W * VIEW_H:
        failures.append(f"{name}: the view is not where expected in the screenshot ({box})")
    elif drawn < MIN_DRAWN_FRACTION * total:
        failures.append(f"{name}: the view in the screenshot is nearly empty ({drawn} of {total} pixels)")
    if colours <= MIN_COLOURS:
        failures.append(f"{name}: the view has only {colours} colours")


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    miner, work = sys.argv[1], os.path.abspath(sys.argv[2])
    os.makedirs(work, exist_ok=True)
    run = os.path.join(work, "run")
    fly = subprocess.run([miner, "fly", "--out", run], capture_output=True, text=True)
    if fly.returncode != 0:
        sys.exit(f"check_report: miner fly failed ({fly.returncode}): {fly.stderr}")
    report = os.path.join(run, "report.html")
    if f"report: {report}" not in fly.stdout:
        sys.exit("check_report: the summary does not name the report's path:\n" + fly.stdout)
    log = read_log(os.path.join(run, "flight_log.csv"))
    t = round(log["t"][-1] / 2 / 0.05) * 0.05
    url = f"file://{report}#t={t:.2f}"
    failures = []
    with tempfile.TemporaryDirectory() as profile:
        # 1. WebGL: the 3D view.
        png_3d = os.path.join(work, "report-3d.png")
        run_3d = chromium(["--window-size=1280,1000", "--dump-dom", "--screenshot=" + png_3d, url], profile)
        errors = [l for l in run_3d.stderr.splitlines() if "Uncaught" in l or "CONSOLE" in l and "rror" in l]
        if errors:
            failures.append("script errors:\n" + "\n".join(errors))
        st = status_of(run_3d.stdout)
        # The second run's window: tall enough for every plot (the layout does not depend on WebGL).
        page_height = PAGE_HEIGHT
        try:
            page_height = 40 + max(int(b.split(",")[1]) + int(b.split(",")[3])
                                   for b in (p.split(":")[1] for p in st["plots"].split(";")))
        except (TypeError, KeyError, ValueError, IndexError):
            pass
        if not os.path.exists(png_3d):
            failures.append("no screenshot with WebGL: " + run_3d.stderr[-2000:])
        else:
            box = [int(v) for v in (st or {}).get("view-rect", "0,0,0,0").split(",")]
            check_view("3D view", run_3d.stdout, st, decode_png(open(png_3d, "rb").read(), box[1] + box[3]), failures, "3d", t, log)
        # 2. No WebGL: the top view, and every plot (the same in both runs) on a tall page.
        # --disable-gpu: no GPU process at all (software compositing), which also makes this
        # run about twice as fast.
        png_top = os.path.join(work, "report-top.png")
        run_top = chromium(["--disable-gpu", "--disable-webgl", "--disable-3d-apis", f"--window-size=1280,{page_height}", "--dump-dom",
                            "--screenshot=" + png_top, url], profile)
        errors = [l for l in run_top.stderr.splitlines() if "Uncaught" in l or "CONSOLE" in l and "rror" in l]
        if errors:
            failures.append("script errors without WebGL:\n" + "\n".join(errors))
        st = status_of(run_top.stdout)
        if not os.path.exists(png_top):
            failures.append("no screenshot without WebGL: " + run_top.stderr[-2000:])
        elif st is None:
            failures.append("no #miner-status without WebGL")
        else:
            plots = {}
            for item in filter(None, st.get("plots", "").split(";")):
                name, box = item.split(":")
                plots[name] = [int(v) for v in box.split(",")]
            bottom = max([b[1] + b[3] for b in plots.values()] + [0])
            if bottom > page_height:
                failures.append(f"the plots reach {bottom} px, below the {page_height} px screenshot")
            png = decode_png(open(png_top, "rb").read(), min(bottom, page_height))
            check_view("top view (no WebGL)", run_top.stdout, st, png, failures, "top", t, log)
            for name in PLOTS:
                if name not in plots:
                    failures.append(f"the report has no plot {name}")
            for name, box in plots.items():
                drawn, total, colours, coloured = area_stats(png, box)
                print(f"  {name}: {box[2]}x{box[3]} px, {100.0 * drawn / max(total, 1):.1f} % drawn, "
                      f"{coloured} coloured pixels, {colours} colours")
                events = name == "plot-events"
                if drawn < 0.02 * total:
                    failures.append(f"the plot {name} is nearly empty in the screenshot")
                elif not events and coloured < MIN_COLOURED:
                    failures.append(f"the plot {name} shows no data lines ({coloured} coloured pixels)")
    if failures:
        sys.exit("check_report: " + "\n".join(failures))
    print("check_report: the report loads without errors; its 3D view, top view and plots draw")


if __name__ == "__main__":
    main()
