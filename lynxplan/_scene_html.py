"""A meshcat scene written straight into one self-contained HTML page (no meshcat server).

meshcat's own ``static_html`` asks its ZMQ server process for the scene, embeds every object's
full geometry (a mesh used five times is sent five times) and replays the commands as
independent ``fetch`` promises. :class:`Scene` packs the same meshcat commands in order, sends
each mesh once and has the page copy it for its other uses (:meth:`Scene.copy_object`), and
sets the camera's orbit target (which meshcat's Python API cannot).
"""

from __future__ import annotations

import base64
import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

#: The page: meshcat's viewer script, then the commands (base64 msgpack) replayed in order.
_PAGE = """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>__TITLE__</title>
<style>body{margin:0}#meshcat-pane{width:100vw;height:100vh;overflow:hidden}</style></head>
<body><div id="meshcat-pane"></div>
<script>__VIEWER__</script>
<script>
const viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
const STEPS = __STEPS__;
const split = (path) => path.split("/").filter((part) => part.length > 0);
for (const step of STEPS) {
  if (typeof step === "string") {
    const raw = atob(step);
    const bytes = new Uint8Array(raw.length);
    for (let i = 0; i < raw.length; i++) bytes[i] = raw.charCodeAt(i);
    viewer.handle_command_bytearray(bytes);
  } else if (step[0] === "copy") {  // [copy, from, to, colour]: one mesh, drawn again
    const source = viewer.scene_tree.find(split(step[1]).concat(["<object>"])).object;
    const copy = source.clone();
    copy.material = source.material.clone();
    copy.material.color.setHex(step[3]);
    viewer.set_object(split(step[2]), copy);
  } else if (step[0] === "on_top") {  // drawn over everything else (after the solids)
    viewer.scene_tree.find(split(step[1])).object.traverse((o) => { o.renderOrder = 10; });
  } else if (step[0] === "target") {  // the camera's orbit target (three.js: y up)
    viewer.controls.target.set(step[1], step[3], -step[2]);
    viewer.controls.update();
  }
}
viewer.set_dirty();
</script></body></html>
"""


class Scene:
    """meshcat commands, in order, for one HTML page."""

    def __init__(self) -> None:
        self.steps: list[Any] = []

    def _send(self, command: Any) -> None:
        import umsgpack

        packed = umsgpack.packb(command.lower())
        self.steps.append(base64.b64encode(packed).decode("ascii"))

    def set_object(self, path: str, geometry: Any, material: Any = None) -> None:
        """Draw ``geometry`` (or a meshcat object, material None) at ``path``."""
        from meshcat.commands import SetObject

        self._send(SetObject(geometry, material, _path(path)))

    def set_transform(self, path: str, matrix: np.ndarray) -> None:
        """Place the node ``path`` by the homogeneous ``matrix`` (4, 4)."""
        from meshcat.commands import SetTransform

        self._send(SetTransform(np.asarray(matrix, dtype=float), _path(path)))

    def set_property(self, path: str, key: str, value: Any) -> None:
        """Set a property (``visible``, ``position``...) of the node ``path``."""
        from meshcat.commands import SetProperty

        self._send(SetProperty(key, value, _path(path)))

    def set_animation(self, animation: Any, play: bool) -> None:
        """The meshcat ``Animation``, played once (from the start when ``play``)."""
        from meshcat.commands import SetAnimation

        self._send(SetAnimation(animation, play=play, repetitions=1))

    def copy_object(self, source: str, path: str, colour: int) -> None:
        """Draw the object at ``source`` again at ``path`` (its geometry shared), in ``colour``."""
        self.steps.append(["copy", source, path, colour])

    def on_top(self, path: str) -> None:
        """Draw the objects under ``path`` after all others (lines over translucent solids)."""
        self.steps.append(["on_top", path])

    def orbit_target(self, point: Sequence[float]) -> None:
        """The point the camera looks at and orbits about, world coordinates (z up)."""
        x, y, z = (float(v) for v in point)
        self.steps.append(["target", x, y, z])

    def html(self, title: str) -> str:
        """The page: meshcat's viewer script inlined, then the steps."""
        import meshcat

        viewer = Path(meshcat.__file__).parent / "viewer" / "dist" / "main.min.js"
        steps = json.dumps(self.steps, separators=(",", ":"))
        return (
            _PAGE.replace("__TITLE__", title.replace("<", "&lt;"))
            .replace("__STEPS__", steps)
            .replace("__VIEWER__", viewer.read_text(encoding="utf-8"))
        )


def _path(text: str) -> Any:
    from meshcat.path import Path as MeshcatPath

    return MeshcatPath(tuple(part for part in text.split("/") if part))


def anim_path(text: str) -> Any:
    """A meshcat path for ``Animation.at_frame`` (anything with a ``path`` attribute)."""

    class _Node:
        path = _path(text)

    return _Node()
