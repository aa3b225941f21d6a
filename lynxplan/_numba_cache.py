"""Whether numba's on-disk cache holds a compiled kernel, read without importing its module.

numba keeps one index file per cached function (next to its source, under ``NUMBA_CACHE_DIR``
or in the user's cache folder): numba's version, a stamp of the source file, and the compiled
versions, each keyed by its signature and the CPU it was compiled for. :func:`cached` locates
the index with numba's own cache classes and reads it without unpickling the signatures (they
name lynxplan's types, and unpickling them imports their modules), so a front end can decide
how to run before any kernel module is imported (``lynxplan._jit``).
"""

from __future__ import annotations

import ast
import pickle
import pickletools
import types
from pathlib import Path
from typing import Any


def cached(kernel: str) -> bool:
    """Whether numba's cache holds a version of ``kernel`` ("module:name", a top-level
    ``cache=True`` function of a lynxplan module) that numba would load in this process: an
    index of this numba version, for the current source, with a version compiled for this CPU
    (its name and features). Where numba's cache classes are not as expected (another numba
    release), True: numba then decides, as it always does."""
    try:
        return _cached(kernel)
    except (AttributeError, TypeError, ImportError, StopIteration):
        return True


def import_numba() -> None:
    """Import what :func:`cached` reads of numba, in the calling thread. Call it before asking
    :func:`cached` in another thread while this one may import numba too: numba's modules import
    each other, and two threads importing them at once can leave one with a partially
    initialised module (an ImportError; ``lynxplan serve``'s start failed so, once in CI)."""
    import llvmlite.binding  # noqa: F401
    import numba  # noqa: F401
    from numba.core import caching, codegen, config  # noqa: F401


def _cached(kernel: str) -> bool:
    import llvmlite.binding as llvm
    from numba.core import caching, codegen, config

    module, name = kernel.split(":")
    path = Path(__file__).parent.joinpath(*module.split(".")[1:]).with_suffix(".py")
    tree = ast.parse(path.read_text(encoding="utf-8"))
    node = next(n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == name)
    first = min([node.lineno, *(d.lineno for d in node.decorator_list)])
    code = _stand_in.__code__.replace(co_filename=str(path), co_firstlineno=first, co_name=name)
    stand_in = types.FunctionType(code, {}, name)
    stand_in.__qualname__ = name
    function_cache: Any = caching.FunctionCache
    index: Any = function_cache(stand_in)._cache_file
    stamp = index._source_stamp  # numba >= 0.64: a hash of the source; older: (mtime, size)
    parts = list(stamp) if isinstance(stamp, tuple) else [stamp]
    try:
        with open(index._index_path, "rb") as file:
            version = pickle.load(file)  # a str
            values = _values(file.read())  # the stamp first, then the versions' keys
    except (OSError, pickle.UnpicklingError, EOFError, ValueError):
        return False
    settings: Any = config  # numba's NUMBA_CPU_NAME and NUMBA_CPU_FEATURES, as numba reads them
    host_features: Any = codegen.get_host_cpu_features
    cpu = settings.CPU_NAME or llvm.get_host_cpu_name()
    features = settings.CPU_FEATURES
    features = host_features() if features is None else features
    return bool(
        version == index._version
        and values[: len(parts)] == parts
        and cpu in values
        and features in values
    )


def _values(data: bytes) -> list[Any]:
    """The values (numbers, strings, bytes) a pickle stream pushes, in order, read without
    running it."""
    return [
        argument
        for opcode, argument, _position in pickletools.genops(data)
        if argument is not None and opcode.name not in _NOT_VALUES
    ]


#: Pickle opcodes whose argument is no value of the stream.
_NOT_VALUES = frozenset(
    {"PROTO", "FRAME", "GET", "BINGET", "LONG_BINGET", "PUT", "BINPUT", "LONG_BINPUT"}
)


def _stand_in() -> None:
    """The code object :func:`cached` renames after a kernel."""
