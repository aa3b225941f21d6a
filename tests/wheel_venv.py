"""lynxplan as a user gets it: a wheel built from this checkout, installed into its own virtual
environment, its commands run from a folder outside the repository.

Used by ``test_installed.py`` and ``test_readme.py`` (one build per test session, shared through
:func:`installed_lynxplan`).

How it is built (``LYNXPLAN_WHEEL_DEPS`` picks the dependencies' source):

1. ``pip wheel --no-deps`` of the checkout (build isolation, hatchling from the registry): the
   wheel a ``pip install .`` builds, with its package data (``lynxplan/_data``).
2. ``python -m venv`` of its own, and ``pip install --no-deps`` of that wheel into it: lynxplan
   is imported from that venv's site-packages only (checked: never from the checkout).
3. The dependencies. Default (``shared``): a ``.pth`` file in the new venv adds the site-packages
   folders of the environment running the tests (read-only, its ``.pth`` files not processed, so
   an editable lynxplan there is invisible). Installing them as a user does (``pip install``
   of the wheel with its dependencies, ``LYNXPLAN_WHEEL_DEPS=install``) took 2 min 41 s on the
   2-core machine (1.6 GB unpacked from the local index) against ~15 s for the shared way; the
   dependency list itself is checked by ``tests/test_dependencies.py``, and ``pip check`` runs
   in the new venv either way.
4. numba's on-disk cache: the checkout's compiled kernels (``__pycache__/*.nbi, *.nbc``) are
   copied next to the installed sources, whose modification times are set to the checkout's
   (numba keys its cache on the source's time and size): what ``lynxplan compile`` would leave
   after installation, without compiling every kernel a second time (1-2 min of CPU on 2 cores).
   A kernel the checkout has not compiled yet compiles in the installed copy, as for a user.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import sysconfig
import time
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
#: Environment variable choosing how the installed wheel gets its dependencies.
DEPS_VARIABLE = "LYNXPLAN_WHEEL_DEPS"


@dataclass(frozen=True)
class Installed:
    """A venv holding the wheel of this checkout."""

    venv: Path
    """The virtual environment's folder."""
    wheel: Path
    """The wheel installed into it."""
    env: dict[str, str]
    """Environment of a user's shell with the venv activated (no PYTHONPATH)."""
    seconds: dict[str, float] = field(default_factory=dict)
    """Wall time of each build step, in [s]."""

    @property
    def bin(self) -> Path:
        return self.venv / "bin"

    @property
    def python(self) -> Path:
        return self.bin / "python"

    def run(
        self, command: list[str] | str, cwd: Path, timeout: float = 600, **kwargs: object
    ) -> subprocess.CompletedProcess[str]:
        """Run ``command`` (a list, or a shell line for ``bash -c``) in ``cwd`` with the venv
        activated; output captured as text."""
        args: list[str] | str = command
        if isinstance(command, str):
            args = ["bash", "-c", command]
        return subprocess.run(
            args,
            cwd=cwd,
            env=self.env,
            capture_output=True,
            text=True,
            timeout=timeout,
            check=False,
            **kwargs,  # type: ignore[call-overload]
        )


_BUILT: dict[str, Installed] = {}


def installed_lynxplan(root: Path) -> Installed:
    """The wheel of this checkout installed into a venv under ``root`` (built once a session)."""
    if "it" not in _BUILT:
        _BUILT["it"] = _build(root)
    return _BUILT["it"]


def _check(command: list[str], **kwargs: object) -> None:
    done = subprocess.run(command, capture_output=True, text=True, check=False, **kwargs)  # type: ignore[call-overload]
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} exited {done.returncode}:\n{done.stderr[-3000:]}")


def _build(root: Path) -> Installed:
    seconds = {}
    began = time.perf_counter()
    dist = root / "dist"
    pip = [sys.executable, "-m", "pip"]
    _check([*pip, "wheel", "--no-deps", "-q", "-w", str(dist), str(REPO)])
    wheel = next(dist.glob("lynxplan-*.whl"))
    seconds["wheel"] = time.perf_counter() - began
    venv = root / "venv"
    began = time.perf_counter()
    _check([sys.executable, "-m", "venv", "--without-pip", str(venv)])
    python = venv / "bin" / "python"
    site = Path(
        subprocess.run(
            [str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
    )
    mode = os.environ.get(DEPS_VARIABLE, "shared")
    if mode == "shared":
        _check([*pip, "--python", str(python), "install", "-q", "--no-deps", str(wheel)])
        (site / "_lynxplan_test_dependencies.pth").write_text("\n".join(_dependency_paths()))
        for name, module in (("pytest", "pytest"),):  # the test extra's command (README)
            script = venv / "bin" / name
            script.write_text(f"#!{python}\nimport sys\nfrom {module} import console_main\n"
                              "sys.exit(console_main())\n")  # fmt: skip
            script.chmod(0o755)
    else:
        _check([*pip, "--python", str(python), "install", "-q", str(wheel)])
    _check([*pip, "--python", str(python), "check"])
    seconds["install"] = time.perf_counter() - began
    began = time.perf_counter()
    _seed_numba_cache(site / "lynxplan")
    seconds["numba cache"] = time.perf_counter() - began
    env = {
        k: v
        for k, v in os.environ.items()
        if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV", "NUMBA_CACHE_DIR")
    }
    home = root / "home"  # the user's data and cache folders (the service's store): not ~
    env.update(
        PATH=f"{venv / 'bin'}{os.pathsep}{env.get('PATH', '')}",
        VIRTUAL_ENV=str(venv),
        XDG_DATA_HOME=str(home / "data"),
        XDG_CACHE_HOME=str(home / "cache"),
        XDG_CONFIG_HOME=str(home / "config"),
        MPLBACKEND="Agg",
    )
    installed = Installed(venv=venv, wheel=wheel, env=env, seconds=seconds)
    where = installed.run([str(python), "-c", "import lynxplan; print(lynxplan.__file__)"], root)
    if not where.stdout.strip().startswith(str(site)):
        raise RuntimeError(f"the venv imports lynxplan from {where.stdout or where.stderr}")
    return installed


def _dependency_paths() -> list[str]:
    """The site-packages folders of the environment running the tests (where the dependencies
    are), without the checkout or anything outside that environment."""
    prefix = Path(sys.prefix).resolve()
    paths = []
    for entry in sys.path:
        path = Path(entry or ".").resolve()
        if path.is_dir() and path.is_relative_to(prefix) and path != REPO:
            paths.append(str(path))
    purelib = sysconfig.get_paths()["purelib"]
    return list(dict.fromkeys([purelib, *paths]))


def _seed_numba_cache(installed: Path) -> None:
    """Copy the checkout's numba cache next to the installed sources that are byte-identical,
    and give those sources the checkout's modification times (numba's cache key)."""
    source = REPO / "lynxplan"
    for index in source.rglob("__pycache__/*.nb[ic]"):
        target = installed / index.relative_to(source)
        py = installed / index.parent.parent.relative_to(source)
        if not py.is_dir():
            continue
        target.parent.mkdir(exist_ok=True)
        shutil.copy2(index, target)
    for module in source.rglob("*.py"):
        copy = installed / module.relative_to(source)
        if copy.is_file() and copy.read_bytes() == module.read_bytes():
            stat = module.stat()
            os.utime(copy, ns=(stat.st_atime_ns, stat.st_mtime_ns))
