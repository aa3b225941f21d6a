"""Files shipped with lynxplan: the AL5's URDF and the example scenarios.

An installed wheel holds them as package data under ``lynxplan/_data/`` (``pyproject.toml``'s
``force-include``: ``urdf/`` -> ``lynxplan/_data/urdf``, ``scenarios/`` ->
``lynxplan/_data/scenarios``), found through :mod:`importlib.resources`; a source checkout (an
editable install, the tests) has them as the checkout's top-level ``urdf/`` and ``scenarios/``.
Every path to a shipped file goes through :func:`shipped_path`: no other module finds them by
its own location in a checkout.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from lynxplan.exceptions import InputError

#: Folder of the package data inside the installed package.
DATA_FOLDER = "_data"

#: The shipped AL5 URDF's file name (in ``urdf/``).
DEFAULT_URDF_NAME = "lynxmotion_al5.urdf"


def default_urdf_path() -> Path:
    """Path of the shipped AL5 URDF (package data when installed, ``urdf/`` in a checkout)."""
    return shipped_path("urdf", DEFAULT_URDF_NAME)


def shipped_path(*parts: str) -> Path:
    """Path of a shipped file or folder, e.g. ``shipped_path("scenarios", "ok_task.yaml")``.

    Args:
        parts: the path below the checkout's top level (``"urdf"`` or ``"scenarios"`` first).

    Raises:
        InputError: nothing of that name is shipped (the names of what is, in the message).
    """
    packaged = resources.files("lynxplan").joinpath(DATA_FOLDER, *parts)
    if packaged.is_file() or packaged.is_dir():
        return Path(str(packaged))
    root = checkout_root()
    if root is not None and root.joinpath(*parts).exists():
        return root.joinpath(*parts)
    raise InputError(f"{'/'.join(parts)}: not shipped with lynxplan; shipped: {_listing(parts)}")


def checkout_root() -> Path | None:
    """The source checkout holding this ``lynxplan`` package (its folder with a
    ``pyproject.toml``), or None for an installed package (its parent is site-packages)."""
    root = Path(str(resources.files("lynxplan"))).parent
    return root if (root / "pyproject.toml").is_file() else None


def _listing(parts: tuple[str, ...]) -> str:
    """The names shipped in the folder ``parts[:-1]`` (the top-level folders for one part)."""
    root = checkout_root()
    folders = [resources.files("lynxplan").joinpath(DATA_FOLDER, *parts[:-1])]
    folders += [] if root is None else [root.joinpath(*parts[:-1])]
    for folder in folders:
        if len(parts) > 1 and folder.is_dir():
            names = sorted(p.name for p in folder.iterdir() if not p.name.startswith((".", "_")))
            return ", ".join(names)
    return "urdf/, scenarios/"


def scenario_path(name: str) -> Path:
    """Path of a shipped scenario file, e.g. ``scenario_path("ok_task.yaml")`` or
    ``scenario_path("planning/p01_free_space.yaml")``."""
    return shipped_path("scenarios", *name.split("/"))
