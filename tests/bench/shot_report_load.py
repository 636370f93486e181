"""How long headless chromium takes to load the shot report of a large shot, against an empty page loaded in
turn in the same run (required: a page under 5 MB that loads in under 2 s more than the empty page).

The shot: 240 frames x 10 tiles (1001-1005, 1011-1015), a 4 x 4 quad chart each, stretched along x by a
different amount each frame and tile; 32^2 rigidity maps with a disk; 512^2 noise textures (the page's worst
case: thumbnails that do not compress). tests/python/test_shot_report.py checks the same page's size and
content; this script times it.

    PYTHONPATH=build/python python3 tests/bench/shot_report_load.py [--reps 5]
"""
import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

TILES = [1001 + i + 10 * j for j in range(2) for i in range(5)]
FRAMES = list(range(1, 241))


def chromium(*args, timeout=60):
    """Runs headless chromium (scripts/setup.sh installs Debian's) with a throw-away profile."""
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    assert exe, "chromium is not on PATH: scripts/setup.sh installs Debian's chromium package"
    profile = tempfile.mkdtemp()
    try:
        return subprocess.run([exe, "--headless=new", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                               "--no-first-run", f"--user-data-dir={profile}", *args],
                              capture_output=True, text=True, timeout=timeout, check=True)
    finally:
        shutil.rmtree(profile, ignore_errors=True)


def write_large_report(dk, folder):
    """Solves the 240-frame x 10-tile shot into `folder` and writes its page; returns (page path, the result
    of deformkit.shot_report)."""
    points, counts, indices, uvs = [], [], [], []
    for tile in TILES:
        i, j = (tile - 1001) % 10, (tile - 1001) // 10
        base = len(points)
        for b in range(5):
            for a in range(5):
                points.append((i + a / 4, j + b / 4, 0.0))
                uvs.append((i + a / 4, j + b / 4))
        for b in range(4):
            for a in range(4):
                counts.append(4)
                indices += [base + b * 5 + a, base + b * 5 + a + 1, base + (b + 1) * 5 + a + 1,
                            base + (b + 1) * 5 + a]
    points, uvs = np.array(points, np.float32), np.array(uvs, np.float32)
    mesh = dk.Mesh(points, np.array(counts, np.int32), np.array(indices, np.int32), uvs,
                   np.array(indices, np.int32))
    tile_of = np.repeat(np.arange(len(TILES)), 25)

    def deformed(frame):
        p = points.copy()
        scale = 1.0 + 0.3 * np.sin(frame / 20.0 + tile_of)
        p[:, 0] = np.floor(points[:, 0]) + (points[:, 0] - np.floor(points[:, 0])) * scale
        return p

    y, x = np.mgrid[0:32, 0:32]
    disk = (np.hypot((x + 0.5) / 32 - 0.5, (y + 0.5) / 32 - 0.5) < 0.25).astype(np.float32)
    rng = np.random.default_rng(7)
    noise = {tile: rng.random((512, 512, 3), np.float32) for tile in TILES}
    log = os.path.join(folder, "shot.jsonl")
    dk.uvwarp_shot(mesh, FRAMES, deformed, {tile: disk for tile in TILES},
                   os.path.join(folder, "redirect.<UDIM>.####.exr"), log=log, iterations=1, sweeps_per_level=[1])
    page = os.path.join(folder, "report.html")
    result = dk.shot_report(log, page, rest=mesh, deformed=deformed, rigidity={t: disk for t in TILES},
                            texture=noise)
    return page, result


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--reps", type=int, default=5, help="loads of each page, alternating (default 5)")
    args = parser.parse_args()
    import deformkit as dk

    folder = tempfile.mkdtemp()
    try:
        page, result = write_large_report(dk, folder)
        if result["problems"] or result["log_lines"] != len(FRAMES) * len(TILES):
            sys.exit(f"shot_report_load: the page's shot is not whole: {result}")
        empty = os.path.join(folder, "empty.html")
        with open(empty, "w") as f:
            f.write("<!DOCTYPE html><title>empty</title>")
        times = {page: [], empty: []}
        for _ in range(args.reps):
            for path in (empty, page):
                start = time.perf_counter()
                dom = chromium("--dump-dom", "file://" + path).stdout
                times[path].append(time.perf_counter() - start)
                if "</html>" not in dom:
                    sys.exit(f"shot_report_load: chromium did not load {path}")
        size = os.path.getsize(page) / 2**20
        loaded, bare = statistics.median(times[page]), statistics.median(times[empty])
        print(f"shot report, {len(FRAMES)} frames x {len(TILES)} tiles: {size:.2f} MB (required under 5 MB)")
        print(f"load, median of {args.reps}: {loaded:.2f} s, empty page {bare:.2f} s: {loaded - bare:.2f} s more "
              f"(required under 2 s), {loaded / bare:.2f}x")
    finally:
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
