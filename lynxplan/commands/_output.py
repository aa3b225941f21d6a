"""Shared helpers for sub-commands: JSON output and number parsing."""

from __future__ import annotations

import json
import math
import sys
from typing import Any

import numpy as np

from lynxplan.exceptions import InputError


def to_jsonable(value: Any) -> Any:
    """Numpy arrays/scalars -> nested lists/floats; NaN -> None (JSON has no NaN)."""
    if isinstance(value, np.ndarray):
        return to_jsonable(value.tolist())
    if isinstance(value, np.generic):
        return to_jsonable(value.item())
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_jsonable(v) for v in value]
    return value


def print_json(value: Any) -> None:
    """Write ``value`` as JSON to stdout, followed by a newline."""
    sys.stdout.write(json.dumps(to_jsonable(value), indent=2) + "\n")


#: Longest JSON value accepted on the command line, in characters.
MAX_JSON_ARGUMENT = 100_000


def parse_json_numbers(text: str, name: str, what: str) -> np.ndarray:
    """A JSON nested list of numbers from the command line -> float array.

    Raises:
        InputError: naming ``name`` for text that is too long, not JSON, nested too deeply, or
            not a (rectangular) list of numbers.
    """
    if len(text) > MAX_JSON_ARGUMENT:
        raise InputError(f"{name}: {len(text)} characters, more than {MAX_JSON_ARGUMENT}")
    try:
        value = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"{name}: not {what} ({exc.msg} at character {exc.pos})") from None
    except RecursionError:
        raise InputError(f"{name}: not {what} (JSON nested too deeply)") from None
    from lynxplan import guards

    return guards.float_array(name, value)


def parse_finite(text: str, name: str) -> float:
    """Parse a float command-line value; InputError naming ``name`` if not a finite number."""
    try:
        value = float(text)
    except ValueError:
        raise InputError(f"{name}: {text!r} is not a number") from None
    if not math.isfinite(value):
        raise InputError(f"{name}: {text!r} is not a finite number")
    return value
