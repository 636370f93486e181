"""The UV warp's options are declared once in the library (deformkit.uv_warp_options()); these tests walk that
declaration and check that every interface knows every option by its name and range: Python's keywords
(snake_case), the `deformkit uvwarp` command line (--kebab-case) and scenes' params (camelCase). For each
option a value in range reaches the solve (read back from the solver, the scene or the redirect map's header)
and values just outside the range are refused with the same message, naming the option as that interface
spells it. The names are checked against a conversion written here."""
import json
import os
import pathlib
import re
import subprocess

import numpy as np
import pytest

import deformkit as dk
from test_uvwarp import disks, plane

OPTIONS = dk.uv_warp_options()
T = 16  # texels per side of the maps


def words(name, separator):
    return re.sub(r"[A-Z]", lambda m: separator + m.group(0).lower(), name)


def in_range(option):
    """A valid value other than the default, chosen from the declared range."""
    default, low, high = option["default"], option["low"], option["high"]
    if option["type"] == "flag":
        return not option["shot_default"]  # differs from a shot's default as well
    if option["type"] == "integer list":
        return [2, 3, 5]
    if option["power_of_two"]:
        return 8
    if option["type"] == "integer":
        return default + 1 if default < high else default - 1
    return float(np.float32((default + high) / 2 if default < high else (low + high) / 2))


def out_of_range(option):
    """Values just outside the declared range (none for a flag: it has two values and both are valid)."""
    low, high = option["low"], option["high"]
    if option["type"] == "flag":
        return []
    if option["type"] == "integer list":
        return [[4, int(high) + 1], [4, -1], [0, 0]]
    if option["type"] == "integer":
        return [int(high) + 1, int(low) - 1] + ([48] if option["power_of_two"] else [])
    return [high + 0.5, low if option["low_open"] else low - 0.5]


def cli_text(value):
    return ",".join(str(v) for v in value) if isinstance(value, list) else str(value)


def same(a, b):
    return a == pytest.approx(b, rel=1e-6) if isinstance(b, float) else a == b


@pytest.fixture(scope="module")
def shot(tmp_path_factory):
    """A plane with UVs, one deformed frame and a rigidity map, as files."""
    folder = tmp_path_factory.mktemp("shot")
    pts, counts, idx, uvs, uv_idx = plane(n=4)
    mesh = dk.Mesh(pts, counts, idx, uvs, uv_idx)
    dk.write_mesh(str(folder / "rest.obj"), mesh)
    moved = dk.Mesh(pts * np.float32([1.5, 1, 1]), counts, idx, uvs, uv_idx)
    dk.write_mesh(str(folder / "anim.0001.obj"), moved)
    dk.write_image(str(folder / "rig.1001.exr"), disks(T)[:, :, None], type="float")
    return folder, mesh


def test_the_declaration_spells_each_name_by_rule():
    assert len({o["name"] for o in OPTIONS}) == len(OPTIONS) > 10
    for o in OPTIONS:
        assert re.fullmatch(r"[a-z]+([A-Z][a-z]+)*", o["name"]), o["name"]
        assert o["python"] == words(o["name"], "_")
        assert o["cli"] == "--" + words(o["name"], "-")
        assert o["meaning"] and o["expected"]


def test_python_takes_every_option_by_its_name_and_range(shot):
    _, mesh = shot
    rigidity = disks(T)
    for o in OPTIONS:
        name, value = o["python"], in_range(o)
        keywords = {name: value}
        solver = dk.UvWarpSolver(mesh, 1001, rigidity, **keywords)
        assert same(solver.options[name], value), name
        for bad in out_of_range(o):
            with pytest.raises(dk.InvalidInput, match=re.escape(f"UvWarpSolver: {name}: is ") + ".*" +
                               re.escape(f"(expected {o['expected']})")):
                dk.UvWarpSolver(mesh, 1001, rigidity, **{name: bad})


def run(*args):
    cli = os.environ.get("DEFORMKIT_CLI")
    if not cli:
        pytest.skip("DEFORMKIT_CLI is not set (ctest sets it)")
    return subprocess.run([cli, *[str(a) for a in args]], capture_output=True, text=True)


def test_the_command_line_takes_every_option_by_its_name_and_range(shot):
    folder, _ = shot
    base = ["uvwarp", "--rest", folder / "rest.obj", "--deformed", folder / "anim.####.obj", "--frames", "1",
            "--rigidity", folder / "rig.<UDIM>.exr"]
    # Every option set at once to a value in range; the map's header records what the solve used.
    args = list(base) + ["--out", folder / "cli" / "redirect.<UDIM>.####.exr"]
    (folder / "cli").mkdir()
    for o in OPTIONS:
        value = in_range(o)
        if o["type"] == "flag":  # a flag on in a shot is turned off as --name=false
            args += [o["cli"] if value else o["cli"] + "=false"]
        else:
            args += [o["cli"], cli_text(value)]
    done = run(*args)
    assert done.returncode == 0, done.stderr
    header = dk.read_image_info(str(folder / "cli" / "redirect.1001.0001.exr"))["attributes"]
    recorded = json.loads(header["deformkit:uvwarp:solver"])
    assert recorded["cells"] == in_range(next(o for o in OPTIONS if o["name"] == "resolution"))
    for o in OPTIONS:
        if o["name"] not in ("resolution", "threads"):  # the grid in use is "cells"; threads change nothing
            assert same(recorded[o["name"]], in_range(o)), o["name"]
    # Each value out of range: exit 2 and one line naming the option as the command spells it.
    for o in OPTIONS:
        for bad in out_of_range(o):
            done = run(*base, "--out", folder / "x" / "r.<UDIM>.####.exr", o["cli"], cli_text(bad))
            assert done.returncode == 2, (o["cli"], bad, done.stderr)
            assert f"{o['cli']}: is " in done.stderr and f"(expected {o['expected']})" in done.stderr, done.stderr
            assert done.stderr.count("\n") == 1


def scene(folder, params):
    path = folder / "scene.json"
    path.write_text(json.dumps({
        "deformkit_scene": 1, "frames": [1, 1],
        "objects": [{"name": "plane", "mesh": "rest.obj",
                     "stack": [{"type": "uvwarp", "rigidity": "rig.<UDIM>.exr", "params": params}]}]}))
    return str(path)


def test_scenes_take_every_option_by_its_name_and_range(shot):
    folder, _ = shot
    values = {o["name"]: in_range(o) for o in OPTIONS}
    stage = dk.read_scene(scene(folder, values)).entries(0)[-1]
    assert stage["type"] == "uvwarp"
    for o in OPTIONS:
        assert same(stage["options"][o["name"]], values[o["name"]]), o["name"]
    for o in OPTIONS:
        for bad in out_of_range(o) + ([1] if o["type"] == "flag" else []):
            expected = re.escape(f"objects[0].stack[0].params.{o['name']}: is ") + ".*" + re.escape(
                f"(expected {o['expected']})")
            with pytest.raises(dk.InvalidInput, match=expected):
                dk.read_scene(scene(folder, {o["name"]: bad}))
    with pytest.raises(dk.InvalidInput, match=r"params.borderWidth: is not a UV-warp option"):
        dk.read_scene(scene(folder, {"borderWidth": 2}))
    # The entry's own "resolution" and the same option in its params: one would be dropped without a word.
    twice = json.loads(pathlib.Path(scene(folder, {"resolution": 32})).read_text())
    twice["objects"][0]["stack"][0]["resolution"] = 64
    (folder / "twice.json").write_text(json.dumps(twice))
    with pytest.raises(dk.InvalidInput, match=re.escape(
            "objects[0].stack[0].params.resolution: is given as well as objects[0].stack[0].resolution "
            "(expected the resolution given once, in either place)")):
        dk.read_scene(str(folder / "twice.json"))


def test_the_live_preset_by_name_in_python_the_command_line_and_scenes(shot):
    """preset='live' / --preset live / "preset": "live" is the library's live preset for the grid's size
    (dk.uv_warp_live_options), warm-started; an option given beside it keeps its value."""
    folder, mesh = shot
    rigidity = disks(T)
    live = dk.uv_warp_live_options(T)
    solver = dk.UvWarpSolver(mesh, 1001, rigidity, preset="live")
    assert {k: solver.options[k] for k in live} == live and live["warm_start"] and live["iterations"] == 1
    mine = dk.UvWarpSolver(mesh, 1001, rigidity, preset="live", iterations=3, resolution=8)
    assert mine.options["iterations"] == 3 and mine.options["resolution"] == 8
    assert mine.options["sweeps_per_level"] == dk.uv_warp_live_options(8)["sweeps_per_level"]
    assert live["refinement_sweeps"] == 0
    shot_options = dk.UvWarpSolver(mesh, 1001, rigidity, preset="shot").options
    assert shot_options["warm_start"] is False and shot_options["refinement_sweeps"] == -1  # by the grid's size
    assert dk.UvWarpSolver(mesh, 1001, rigidity).options["refinement_sweeps"] == 0  # a library solver: none
    with pytest.raises(dk.InvalidInput, match=r"UvWarpSolver: preset: is 'fast' \(expected shot or live\)"):
        dk.UvWarpSolver(mesh, 1001, rigidity, preset="fast")

    base = ["uvwarp", "--rest", folder / "rest.obj", "--deformed", folder / "anim.####.obj", "--frames", "1",
            "--rigidity", folder / "rig.<UDIM>.exr"]
    for name, extra, iterations in (("live", [], 1), ("live3", ["--iterations", "3"], 3)):
        (folder / name).mkdir()
        done = run(*base, "--out", folder / name / "r.<UDIM>.####.exr", "--preset", "live", *extra)
        assert done.returncode == 0, done.stderr
        used = json.loads(dk.read_image_info(str(folder / name / "r.1001.0001.exr"))["attributes"][
            "deformkit:uvwarp:solver"])
        assert used["iterations"] == iterations and used["warmStart"] is True
        assert used["sweepsPerLevel"] == live["sweeps_per_level"]
        assert used["coarseRelaxation"] == pytest.approx(live["coarse_relaxation"])
    done = run(*base, "--out", folder / "x" / "r.<UDIM>.####.exr", "--preset", "fast")
    assert done.returncode == 2 and "--preset" in done.stderr

    path = folder / "scene.json"
    path.write_text(json.dumps({
        "deformkit_scene": 1, "frames": [1, 1],
        "objects": [{"name": "plane", "mesh": "anim.####.obj", "restFrame": 1,
                     "stack": [{"type": "uvwarp", "rigidity": "rig.<UDIM>.exr", "preset": "live",
                                "params": {"iterations": 2}}]}]}))
    stage = dk.read_scene(str(path)).entries(0)[-1]
    assert stage["preset"] == "live" and stage["options"]["iterations"] == 2
    done = run("eval", path, "--out", folder / "eval", "--no-previews")
    assert done.returncode == 0, done.stderr
    used = json.loads(dk.read_image_info(str(folder / "eval" / "plane.redirect.1001.0001.exr"))["attributes"][
        "deformkit:uvwarp:solver"])
    assert used["iterations"] == 2 and used["warmStart"] is True and used["sweepsPerLevel"] == live["sweeps_per_level"]
    path.write_text(path.read_text().replace('"live"', '"fast"'))
    with pytest.raises(dk.InvalidInput, match=r"objects\[0\]\.stack\[0\]\.preset: is 'fast'"):
        dk.read_scene(str(path))
