"""The Maya set-up commands (plugins/maya/scripts/deformkit_maya.py) against a stand-in for maya.cmds that
records the calls (no Maya here): the nodes made, the attributes set and the connections, which are what a
set-up is in Maya."""
import importlib.util
import pathlib
import sys
import types

import pytest

SCRIPT = pathlib.Path(__file__).resolve().parents[2] / "plugins" / "maya" / "scripts" / "deformkit_maya.py"


class FakeCmds(types.ModuleType):
    """maya.cmds with a selection of one mesh transform 'body' (shape 'bodyShape'); records calls."""

    def __init__(self):
        super().__init__("maya.cmds")
        self.calls = []
        self.connections = []
        self.attributes = {}

    def _record(self, command, *args, **kwargs):
        self.calls.append((command, args, kwargs))

    def ls(self, *args, **kwargs):
        return ["bodyShape"] if kwargs.get("type") == "mesh" else ["body"]

    def createNode(self, kind, **kwargs):
        self._record("createNode", kind)
        return kind + "1"

    def shadingNode(self, kind, **kwargs):
        self._record("shadingNode", kind, **kwargs)
        return kwargs.get("name", kind + "1")

    def duplicate(self, node, name):
        return [name]

    def listRelatives(self, node, **kwargs):
        return [node + "Shape"]

    def hide(self, node):
        self._record("hide", node)

    def connectAttr(self, source, destination):
        self.connections.append((source, destination))

    def setAttr(self, plug, *values, **kwargs):
        self.attributes[plug] = values[0] if len(values) == 1 else values

    def error(self, message):
        raise RuntimeError(message)


@pytest.fixture()
def script(monkeypatch):
    cmds = FakeCmds()
    maya = types.ModuleType("maya")
    maya.cmds = cmds
    monkeypatch.setitem(sys.modules, "maya", maya)
    monkeypatch.setitem(sys.modules, "maya.cmds", cmds)
    spec = importlib.util.spec_from_file_location("deformkit_maya_under_test", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module, cmds


def test_create_redirect_wires_the_meshes_time_and_a_file_texture_that_reads_each_frames_map(script):
    dk, cmds = script
    node = dk.create_redirect("rig.<UDIM>.exr", "maps/redirect.<UDIM>.####.exr", tile=1002, preset="live")
    assert node == "dkUvRedirect1"
    assert ("bodyShape.outMesh", node + ".inMesh") in cmds.connections
    assert ("bodyShapeUvRestShape.outMesh", node + ".restMesh") in cmds.connections
    assert ("time1.outTime", node + ".time") in cmds.connections
    # Maya computes outFile only when something reads it: the file texture's name is connected to it.
    assert ("shadingNode", ("file",), {"asTexture": True, "name": node + "Map"}) in cmds.calls
    assert (node + ".outFile", node + "Map.fileTextureName") in cmds.connections
    assert cmds.attributes[node + ".preset"] == "live"
    assert cmds.attributes[node + ".tile"] == 1002
    assert cmds.attributes[node + ".rigidity"] == "rig.<UDIM>.exr"
