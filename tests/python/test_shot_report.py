"""The shot report as a farm TD opens it: a real UV-warp shot (the rigged Fox of tests/data/fox, 24 frames, its
own UV layout) written as files with its log, its page made by `deformkit.shot_report`, then opened by a real
headless browser (Debian's chromium). The page's numbers are checked against the log, computed here apart from
the library; the browser's DOM holds them and its screenshot shows plots and heatmaps (checked for content: the
plot line's and the heatmap's colours, not pixels). A 240-frame x 10-tile shot gives a page under 5 MB that the
browser loads whole (its load time is timed by tests/bench/shot_report_load.py)."""
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile

import numpy as np

import deformkit as dk

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "scripts"))
from uvwarp_rigged_figures import chart_texels, rigid_disks  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "bench"))
from shot_report_load import TILES, chromium, write_large_report  # noqa: E402

SHOT = os.path.join(os.path.dirname(__file__), "..", "data", "fox")
T = 128


def page_data(html):
    return json.loads(re.search(r'id="deformkit-shot">(.*?)</script>', html, re.S).group(1))


def test_the_page_of_a_rigged_shot_holds_the_logs_figures_and_shows_plots_and_heatmaps():
    folder = tempfile.mkdtemp()
    try:
        rest = dk.read_mesh(os.path.join(SHOT, "rest.obj"))
        rigidity = rigid_disks(chart_texels(rest, T), T)
        dk.write_image(os.path.join(folder, "rig.1001.exr"), rigidity[..., None])
        os.makedirs(os.path.join(folder, "out"))
        log = os.path.join(folder, "shot.jsonl")
        # As `deformkit uvwarp` runs it: every input a file, so the report finds them from the maps' headers.
        cli = os.environ.get("DEFORMKIT_CLI", "deformkit")
        subprocess.run([cli, "uvwarp", "--rest", os.path.join(SHOT, "rest.obj"), "--deformed",
                        os.path.join(SHOT, "anim.####.obj"), "--frames", "1-24", "--rigidity",
                        os.path.join(folder, "rig.<UDIM>.exr"), "--out",
                        os.path.join(folder, "out", "redirect.<UDIM>.####.exr"), "--log", log],
                       check=True, capture_output=True)
        page = os.path.join(folder, "report.html")
        result = dk.shot_report(log, page, title="Fox running")
        assert result["notes"] == [] and result["problems"] == 0 and result["log_lines"] == 24, result

        # The figures, from the log, apart from the library.
        lines = [json.loads(line) for line in open(log)]
        removed = [l["metrics"]["rigid_stretch_removed"] for l in lines]
        worst = int(np.argmin(removed))
        html = open(page, encoding="utf-8").read()
        data = page_data(html)
        tile = data["tiles"][0]
        assert tile["frames"] == list(range(1, 25))
        assert tile["rigid_stretch_removed"] == removed
        assert tile["inverted_triangles"] == [l["metrics"]["inverted_triangles"] for l in lines]
        assert tile["off_chart_texels"] == [l["metrics"]["off_chart_texels"] for l in lines]
        assert tile["seconds"] == [l["seconds"]["total"] for l in lines]
        assert tile["worst_frame"] == worst + 1
        row = re.search(r'<tr data-object="" data-tile="1001"[^>]*>', html).group(0)
        assert f'data-median-removed="{statistics.median(removed)!r}"' in row or \
            float(re.search(r'data-median-removed="([^"]+)"', row).group(1)) == statistics.median(removed)
        assert float(re.search(r'data-worst-removed="([^"]+)"', row).group(1)) == removed[worst]
        assert f"Worst frame {worst + 1}: {100 * removed[worst]:.1f}% of the rigid stretch removed" in html
        assert "measured again from its files: the same" in html
        # The rerun line made from the headers runs the shot again: the same bytes.
        rerun = re.search(r"<pre>(deformkit uvwarp .*?)   # made from the maps", html).group(1)
        rerun = rerun.replace("&lt;", "<").replace("&gt;", ">").replace("&amp;", "&").replace("&quot;", '"')
        again = os.path.join(folder, "again")
        os.makedirs(again)
        subprocess.run(rerun.replace(os.path.join(folder, "out"), again).replace("deformkit ", f"'{cli}' ", 1),
                       shell=True, check=True, capture_output=True)
        for frame in (1, worst + 1, 24):
            name = f"redirect.1001.{frame:04d}.exr"
            assert np.array_equal(dk.read_image(os.path.join(again, name)),
                                  dk.read_image(os.path.join(folder, "out", name))), name

        # The browser's DOM holds the figures; its screenshot shows the plots and the heatmaps.
        dom = chromium("--dump-dom", "file://" + page).stdout
        assert page_data(dom) == data
        assert 'data-tile="1001"' in dom and "<svg" in dom
        shot = os.path.join(folder, "screen.png")
        chromium("--window-size=1400,1300", f"--screenshot={shot}", "file://" + page)
        pixels = (dk.read_image(shot)[..., :3] * 255).round().astype(int)

        def near(colour, tolerance=12):
            return int((np.abs(pixels - np.array(colour)).max(axis=-1) <= tolerance).sum())

        assert near((0x20, 0x60, 0xc0), 30) > 200, "no plot line in the screenshot"
        assert near((0xd0, 0x20, 0x20), 30) > 50, "no worst-frame marker in the screenshot"
        # The heatmaps: viridis's dark purple (#440154, no stretch left) on rigid content, the charts' elastic
        # grey, the chart borders' dark lines.
        for colour in [(0x44, 0x01, 0x54), (204, 204, 204), (38, 38, 38)]:
            assert near(colour, 25) > 200, f"no {colour} in the screenshot"
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def test_a_shot_of_240_frames_and_10_tiles_gives_a_page_under_5_mb_that_chromium_loads():
    folder = tempfile.mkdtemp()
    try:
        page, result = write_large_report(dk, folder)
        assert result["log_lines"] == 2400 and result["problems"] == 0 and result["notes"] == [], result
        size = os.path.getsize(page)
        print(f"page: {size / 2**20:.2f} MB for 240 frames x 10 tiles, {len(result['files']) - 1} pictures beside")
        assert size < 5 * 2**20
        data = page_data(open(page, encoding="utf-8").read())
        assert [t["tile"] for t in data["tiles"]] == TILES and all(len(t["frames"]) == 240 for t in data["tiles"])
        # Its load time against an empty page is a benchmark (tests/bench/shot_report_load.py); here the
        # browser loads it whole.
        assert page_data(chromium("--dump-dom", "file://" + page).stdout) == data
    finally:
        shutil.rmtree(folder, ignore_errors=True)
