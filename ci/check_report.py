#!/usr/bin/env python3
"""The flight report opens in headless Chromium and its 3D view draws (REQ-REPORT-003).

cites: REQ-REPORT-003

usage: check_report.py MINER_BINARY WORK_DIR

Runs `miner fly --out WORK_DIR/run`, then loads WORK_DIR/run/report.html in headless
Chromium (software WebGL through SwiftShader) twice: once dumping the DOM after the
scripts ran (the viewer writes its state into #miner-status: "drawn" and the number of
pixels that differ from the background, or "error: ..."), once taking a screenshot,
which is decoded here (PNG, zlib only) to check that the 3D view's area holds a picture.
"""
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
           "--user-data-dir=" + profile, "--virtual-time-budget=15000",
           "--enable-logging=stderr", "--v=0"] + args
    return subprocess.run(cmd, capture_output=True, text=True, timeout=240)


def decode_png(data):
    """RGB(A) 8-bit non-interlaced PNG -> (width, height, channels, rows of bytes)."""
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
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line))
        prev = line
    return width, height, channels, rows


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
    url = "file://" + report
    failures = []
    with tempfile.TemporaryDirectory() as profile:
        dom = chromium(["--dump-dom", url], profile)
        status = re.search(r'id="miner-status"[^>]*data-state="([^"]*)"(?:[^>]*data-pixels="(\d+)")?', dom.stdout)
        if not status:
            failures.append("no #miner-status in the dumped DOM (did the page load?)\n" + dom.stderr[-2000:])
        else:
            state, pixels = status.group(1), int(status.group(2) or 0)
            print(f"viewer state: {state}, {pixels} drawn pixels of {VIEW_W * VIEW_H}")
            if state != "drawn":
                failures.append(f"the viewer reports '{state}'")
            elif pixels < MIN_DRAWN_FRACTION * VIEW_W * VIEW_H:
                failures.append(f"only {pixels} pixels drawn")
        errors = [l for l in dom.stderr.splitlines() if "Uncaught" in l or "CONSOLE" in l and "rror" in l]
        if errors:
            failures.append("script errors:\n" + "\n".join(errors))

        png = os.path.join(work, "report.png")
        shot = chromium(["--window-size=1280,1000", "--screenshot=" + png, url], profile)
        if not os.path.exists(png):
            failures.append("no screenshot: " + shot.stderr[-2000:])
        else:
            w, h, ch, rows = decode_png(open(png, "rb").read())
            # The 3D view is the area cleared to its background colour: the rows and columns
            # where that colour is common (anti-aliased text elsewhere has a few such pixels).
            row_hits, col_hits = [0] * h, [0] * w
            for y in range(h):
                row = rows[y]
                for x in range(w):
                    if tuple(row[x * ch:x * ch + 3]) == VIEW_BACKGROUND:
                        row_hits[y] += 1
                        col_hits[x] += 1
            ys = [y for y in range(h) if row_hits[y] >= 0.2 * VIEW_W]
            xs = [x for x in range(w) if col_hits[x] >= 0.2 * min(VIEW_H, h)]
            if len(xs) < 100 or len(ys) < 100:
                failures.append("the screenshot shows no 3D view (no pixels of its background colour)")
            else:
                x0, x1, y0, y1 = min(xs), max(xs), min(ys), max(ys)
                drawn, colours, total = 0, set(), 0
                for y in range(y0, y1 + 1):
                    row = rows[y]
                    for x in range(x0, x1 + 1):
                        px = tuple(row[x * ch:x * ch + 3])
                        total += 1
                        colours.add(px)
                        if sum(abs(p - q) for p, q in zip(px, VIEW_BACKGROUND)) > 24:
                            drawn += 1
                print(f"screenshot: view {x1 - x0 + 1}x{y1 - y0 + 1} px at ({x0},{y0}), "
                      f"{100.0 * drawn / total:.1f} % drawn, {len(colours)} colours")
                if drawn < MIN_DRAWN_FRACTION * total:
                    failures.append(f"the 3D view in the screenshot is nearly empty ({drawn} of {total} pixels)")
                if len(colours) <= MIN_COLOURS:
                    failures.append(f"the 3D view has only {len(colours)} colours")
    if failures:
        sys.exit("check_report: " + "\n".join(failures))
    print("check_report: the report loads without errors and its 3D view draws")


if __name__ == "__main__":
    main()
