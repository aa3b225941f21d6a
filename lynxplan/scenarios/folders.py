"""Output folders that never lose a user's file, written all together or not at all.

**Ownership.** Every folder lynxplan writes holds a manifest (:data:`MARKER`, JSON) naming each
file it wrote with its SHA-256. A file is lynxplan's own when the manifest names it and its content
is unchanged; anything else in the folder (a file or folder the user added, an output the user
edited) is foreign, and lynxplan deletes or replaces only its own files:

- re-running into a folder lynxplan wrote works without ``force``; the previous outputs are
  replaced as a whole (an output the new run does not write, e.g. a plot ``--quick`` skips, goes);
- a folder holding foreign files is refused (:class:`OutputFolderError`, naming one; the CLI exits
  2) unless ``force=True``; a forced run replaces lynxplan's outputs (edited ones included) and
  leaves every foreign file in place. The manifest remembers the foreign files a forced run found
  (``kept``), so re-running works without ``force`` again until another foreign file appears;
- a foreign file where the run writes an output of the same name is never overwritten: the run is
  refused, even with ``force``.

**Atomicity.** A run writes into a staging folder next to the output folder
(``.NAME.staging-PID-XXXXXXXX``, whose manifest names the process: pid, start time, host). At the
end the foreign files are hard-linked into it (the same files, not copies), the previous folder is
moved aside (``.NAME.previous-PID-XXXXXXXX``), the staging folder renamed into place, and the
previous folder's own files and second links removed. So a failed, interrupted or SIGKILLed run
leaves the previous outputs intact. The next run into the folder removes the staging folders of
dead lynxplan runs (known by name and manifest, never another folder) and moves back a previous
folder a killed run displaced. Where the file system cannot hard-link (FAT, some network shares)
the new outputs are moved in file by file instead: foreign files are safe, the swap is not atomic.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import json
import os
import re
import shutil
import socket
import stat
from collections.abc import Iterable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lynxplan.exceptions import LynxplanError

#: The manifest in every output (and staging) folder lynxplan writes.
MARKER = ".lynxplan-output"
#: The manifest and the temporary file it is written through: lynxplan's in every folder.
_MANIFEST_NAMES = (MARKER, f"{MARKER}.partial")
#: Errors of ``os.link`` that mean the file system has no hard links (then files are moved in).
_NO_HARD_LINKS = frozenset(
    {errno.EPERM, errno.ENOTSUP, errno.EOPNOTSUPP, errno.EXDEV, errno.EMLINK, errno.ENOSYS}
)
_LEGACY_MARKER = "written by lynxplan"


class OutputFolderError(LynxplanError):
    """The output folder cannot be used (not creatable, or holding files lynxplan did not write).

    Attributes:
        path: The output folder.
    """

    def __init__(self, path: Path, reason: str) -> None:
        self.path = path
        super().__init__(f"output folder {path}: {reason}")


@dataclass(frozen=True)
class _Scan:
    """What an output folder holds.

    Attributes:
        own: Files lynxplan wrote, unchanged (paths relative to the folder, ``/``-separated).
        edited: Files lynxplan wrote and someone changed since.
        foreign: Files and folders lynxplan did not write (a foreign folder as one entry).
        kept: Foreign entries a forced run found and kept (re-runs accept them).
    """

    own: tuple[str, ...] = ()
    edited: tuple[str, ...] = ()
    foreign: tuple[str, ...] = ()
    kept: frozenset[str] = field(default_factory=frozenset)


def _digest(path: str | Path) -> str:
    sha = hashlib.sha256()
    with open(path, "rb") as file:
        for block in iter(lambda: file.read(1 << 20), b""):
            sha.update(block)
    return sha.hexdigest()


def _read_manifest(folder: Path) -> dict[str, Any] | None:
    """The folder's manifest; a pre-manifest marker (plain text) names the artifacts of its
    ``report.json`` (unverified: no digests); None without a readable marker."""
    try:
        text = (folder / MARKER).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return None
    if text.startswith(_LEGACY_MARKER):
        try:
            report = json.loads((folder / "report.json").read_text(encoding="utf-8"))
            names = [str(name) for name in report["artifacts"]] + ["report.json"]
        except (OSError, ValueError, KeyError, TypeError):
            names = []
        return {"files": dict.fromkeys(names)}
    try:
        data = json.loads(text)
    except ValueError:
        return None
    return data if isinstance(data, dict) else None


def _files(manifest: Mapping[str, Any] | None) -> dict[str, list[str] | None]:
    """Relative path -> accepted SHA-256 digests (None: any content) from a manifest."""
    files = manifest.get("files") if manifest else None
    if not isinstance(files, dict):
        return {}
    accepted: dict[str, list[str] | None] = {}
    for name, digest in files.items():
        if isinstance(digest, str):
            accepted[str(name)] = [digest]
        elif isinstance(digest, list):
            accepted[str(name)] = [str(d) for d in digest]
        elif digest is None:
            accepted[str(name)] = None
    return accepted


def _parents(name: str) -> list[str]:
    """The folders above a relative path: ``a/b/c.png`` -> ``a``, ``a/b``."""
    parts = name.split("/")
    return ["/".join(parts[:i]) for i in range(1, len(parts))]


def _scan(out: Path) -> _Scan:
    """Sort what ``out`` holds into own, edited and foreign entries (symlinks never followed)."""
    if not out.is_dir():
        return _Scan()
    manifest = _read_manifest(out)
    files = _files(manifest)
    folders = {folder for name in files for folder in _parents(name)}
    own: list[str] = []
    edited: list[str] = []
    foreign: list[str] = []

    def walk(folder: str, prefix: str) -> None:
        with os.scandir(folder) as entries:
            for entry in sorted(entries, key=lambda e: e.name):
                rel = prefix + entry.name
                if rel in _MANIFEST_NAMES:
                    continue
                if entry.is_dir(follow_symlinks=False):
                    if rel in folders:
                        walk(entry.path, rel + "/")
                    else:
                        foreign.append(rel)
                elif rel in files and entry.is_file(follow_symlinks=False):
                    accepted = files[rel]
                    unchanged = accepted is None or _digest(entry.path) in accepted
                    (own if unchanged else edited).append(rel)
                else:
                    foreign.append(rel)

    walk(str(out), "")
    kept = manifest.get("kept") if manifest else None
    kept_set = frozenset(str(k) for k in kept) if isinstance(kept, list) else frozenset()
    return _Scan(tuple(own), tuple(edited), tuple(foreign), kept_set)


def _check(out: Path, scan: _Scan, force: bool) -> None:
    """Refuse a folder holding foreign or edited files, unless forced."""
    if force:
        return
    if scan.edited:
        raise OutputFolderError(
            out,
            f"{scan.edited[0]} was changed after lynxplan wrote it; save it elsewhere, or pass "
            "--force to replace lynxplan's outputs",
        )
    new = [name for name in scan.foreign if name not in scan.kept]
    if new:
        more = f" (and {len(new) - 1} more)" if len(new) > 1 else ""
        raise OutputFolderError(
            out,
            f"holds {new[0]}{more}, which lynxplan did not write; choose another --out, or pass "
            "--force to replace only lynxplan's outputs (files it did not write stay)",
        )


def _start_time(pid: int) -> int | None:
    """The process's start time in clock ticks since boot (Linux), to tell a reused pid."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
        return int(text.rsplit(")", 1)[1].split()[19])
    except (OSError, ValueError, IndexError):
        return None


def _identity() -> dict[str, Any]:
    pid = os.getpid()
    return {"pid": pid, "started": _start_time(pid), "host": socket.gethostname()}


def _alive(pid: int, started: Any) -> bool:
    """Whether process ``pid`` (started at ``started``, or unknown) still runs."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass
    now = _start_time(pid)
    return not (isinstance(started, int) and now is not None and now != started)


def _leftovers(out: Path) -> Iterator[tuple[str, int, Path]]:
    """The (kind, pid, path) of the staging and previous folders named after ``out``."""
    pattern = re.compile(rf"\.{re.escape(out.name)}\.(staging|previous)-(\d+)-[0-9a-z_]{{8}}")
    with os.scandir(out.parent) as entries:
        names = sorted(e.name for e in entries if e.is_dir(follow_symlinks=False))
    for name in names:
        match = pattern.fullmatch(name)
        if match:
            yield match[1], int(match[2]), out.parent / name


def clean_stale(out: Path) -> None:
    """Tidy up after killed runs into ``out``: move back a previous folder a run displaced and did
    not replace; remove the foreign files' second links and lynxplan's files from a previous
    folder; remove the staging folders of dead lynxplan runs on this host. Folders of live runs,
    of other hosts, and any folder without lynxplan's manifest naming its process stay."""
    if not out.parent.is_dir():
        return
    leftovers = list(_leftovers(out))
    for kind, pid, path in leftovers:  # previous folders first: they may hold foreign originals
        if kind != "previous" or (_alive(pid, None) and pid != os.getpid()):
            continue
        if not os.path.lexists(out):
            os.replace(path, out)
        else:
            _discard(path, out, force=False)
    here = socket.gethostname()
    for kind, pid, path in leftovers:
        manifest = _read_manifest(path) if kind == "staging" else None
        if (
            manifest is not None
            and manifest.get("pid") == pid
            and manifest.get("host") == here
            and not _alive(pid, manifest.get("started"))
        ):
            shutil.rmtree(path, ignore_errors=True)


def _same_file(a: Path, b: Path) -> bool:
    try:
        sa, sb = os.lstat(a), os.lstat(b)
    except OSError:
        return False
    return (sa.st_dev, sa.st_ino) == (sb.st_dev, sb.st_ino)


def _discard(old: Path, out: Path, *, force: bool) -> None:
    """Empty and remove a folder a swap moved aside: lynxplan's files in it (edited ones only
    when forced) and the second links of files also in ``out`` go; any other file (one a user
    wrote into the old folder during the swap) is moved back into ``out`` or, if its name is
    taken there, left where it is with the folder."""
    files = _files(_read_manifest(old))
    for root, folders, names in os.walk(old, topdown=False):
        links = [f for f in folders if os.path.islink(os.path.join(root, f))]
        for name in [*names, *links]:
            path = Path(root, name)
            rel = path.relative_to(old).as_posix()
            target = out / rel
            accepted = files.get(rel, [])
            own = rel in files and (force or accepted is None or _digest(path) in accepted)
            if rel in _MANIFEST_NAMES or own or _same_file(path, target):
                path.unlink()
            elif not os.path.lexists(target):
                with contextlib.suppress(OSError):
                    target.parent.mkdir(parents=True, exist_ok=True)
                    os.rename(path, target)
        for name in folders:
            with contextlib.suppress(OSError):
                os.rmdir(os.path.join(root, name))
    with contextlib.suppress(OSError):
        os.rmdir(old)


@contextmanager
def _locked(folder: Path) -> Iterator[None]:
    """Hold an exclusive lock on ``folder`` (runs into its sub-folders check and swap one at a
    time); without ``fcntl`` or where the file system cannot lock, no lock."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - Windows
        yield
        return
    fd = os.open(folder, os.O_RDONLY)
    try:
        with contextlib.suppress(OSError):
            fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)


def _write_manifest(folder: Path, content: Mapping[str, Any]) -> None:
    """Write the manifest through a temporary file renamed over it (never half written)."""
    text = json.dumps({"written_by": "lynxplan", **content}, indent=1, sort_keys=True) + "\n"
    partial = folder / _MANIFEST_NAMES[1]
    partial.write_text(text, encoding="utf-8")
    os.replace(partial, folder / MARKER)


def _make_staging(out: Path) -> Path:
    """A new staging folder next to ``out`` (mode from the umask), its manifest naming us."""
    while True:
        staging = out.parent / f".{out.name}.staging-{os.getpid()}-{os.urandom(4).hex()}"
        try:
            os.mkdir(staging)
            break
        except FileExistsError:
            continue
    _write_manifest(staging, {"state": "staging", **_identity()})
    return staging


def _written(staging: Path) -> list[str]:
    """The files a run wrote into ``staging`` (relative, sorted), the manifest left out."""
    names = []
    for root, _, files in os.walk(staging):
        for name in files:
            rel = Path(root, name).relative_to(staging).as_posix()
            if rel not in _MANIFEST_NAMES:
                names.append(rel)
    return sorted(names)


def _clash(foreign: Iterable[str], written: Iterable[str]) -> str | None:
    """The first foreign entry whose name a new output takes (the same path, or one inside it)."""
    taken = {prefix for name in written for prefix in (*_parents(name), name)}
    return next((name for name in foreign if name in taken), None)


def _link_tree(source: Path, target: Path) -> None:
    """Hard-link ``source`` (a file, a symlink, or a folder's whole tree) as ``target``."""
    if source.is_dir() and not source.is_symlink():
        os.mkdir(target)
        os.chmod(target, stat.S_IMODE(os.lstat(source).st_mode))
        for entry in sorted(os.listdir(source)):
            _link_tree(source / entry, target / entry)
    else:
        os.link(source, target, follow_symlinks=False)


def folder_name(name: object, path: str | Path) -> str:
    """The default output folder's name for a scenario: its ``name`` with every run of characters
    other than letters, digits, ``.``, ``_`` and ``-`` made one ``_`` ("free motion (report
    example)" -> ``free_motion_report_example``); without a usable name, the file's stem."""
    for text in (str(name or ""), Path(path).stem):
        slug = re.sub(r"[^A-Za-z0-9._-]+", "_", text).strip("._-")
        if slug:
            return slug
    return "run"


def _target(out_dir: str | Path) -> Path:
    """The output folder as an absolute path (a symlink to a folder: the folder it points to)."""
    out = Path(os.path.abspath(out_dir))
    if out.is_symlink():
        out = Path(os.path.realpath(out))
    if out.parent == out:
        raise OutputFolderError(out, "cannot be the root folder")
    return out


@contextmanager
def staged_outputs(out_dir: str | Path, *, force: bool = False) -> Iterator[Path]:
    """A staging folder whose files replace lynxplan's outputs in ``out_dir`` if the block
    succeeds; files lynxplan did not write stay (see the module docstring).

    Args:
        out_dir: The output folder (created with its parents if missing).
        force: Use a folder holding files lynxplan did not write (they stay) or outputs a user
            edited (they are replaced).

    Raises:
        OutputFolderError: ``out_dir`` cannot be created, holds foreign or edited files (without
            ``force``), or holds a foreign file where the run writes an output.
    """
    out = _target(out_dir)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        with _locked(out.parent):
            clean_stale(out)
            if os.path.lexists(out) and not out.is_dir():
                raise OutputFolderError(out, "exists and is not a folder")
            scan = _scan(out)
            _check(out, scan, force)
            staging = _make_staging(out)
    except OSError as exc:
        raise OutputFolderError(out, f"cannot be created ({exc.strerror or exc})") from exc
    accepted = scan.kept | (frozenset(scan.foreign) if force else frozenset())
    try:
        yield staging
        with _locked(out.parent):
            _commit(staging, out, force=force, accepted=accepted)
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def _commit(staging: Path, out: Path, *, force: bool, accepted: frozenset[str]) -> None:
    """Put the staged outputs in place of lynxplan's previous ones, foreign files kept."""
    scan = _scan(out)
    if scan.edited and not force:
        _check(out, _Scan(edited=scan.edited), force=False)
    written = _written(staging)
    clash = _clash(scan.foreign, written)
    if clash is not None:
        raise OutputFolderError(
            out,
            f"holds {clash}, which lynxplan did not write, where this run writes an output; "
            "move or rename it (lynxplan never overwrites it, not even with --force)",
        )
    manifest = {
        "state": "complete",
        **_identity(),
        "files": {name: _digest(staging / name) for name in written},
        "kept": [name for name in scan.foreign if name in accepted],
    }
    if not out.is_dir():
        _write_manifest(staging, manifest)
        os.replace(staging, out)
        return
    try:
        for name in scan.foreign:
            (staging / name).parent.mkdir(parents=True, exist_ok=True)
            _link_tree(out / name, staging / name)
    except OSError as exc:
        if exc.errno not in _NO_HARD_LINKS:
            raise
        _move_in(staging, out, scan, manifest)
        return
    _write_manifest(staging, manifest)
    with contextlib.suppress(OSError):
        os.chmod(staging, stat.S_IMODE(os.stat(out).st_mode))
    previous = out.parent / f".{out.name}.previous-{os.getpid()}-{os.urandom(4).hex()}"
    os.replace(out, previous)
    try:
        os.replace(staging, out)
    except OSError:
        os.replace(previous, out)
        raise
    _discard(previous, out, force=force)


def _move_in(staging: Path, out: Path, scan: _Scan, manifest: Mapping[str, Any]) -> None:
    """Without hard links: move the new outputs into ``out`` file by file, then remove the old
    outputs not written again. Until the end the manifest accepts any content of the old and the
    new names (a run killed in between leaves a folder the next run still recognises)."""
    written: dict[str, Any] = manifest["files"]
    old = [*scan.own, *scan.edited]
    _write_manifest(out, {**manifest, "files": dict.fromkeys([*old, *written])})
    for name in written:
        (out / name).parent.mkdir(parents=True, exist_ok=True)
        os.replace(staging / name, out / name)
    for name in old:
        if name not in written:
            with contextlib.suppress(FileNotFoundError):
                (out / name).unlink()
    _write_manifest(out, manifest)
