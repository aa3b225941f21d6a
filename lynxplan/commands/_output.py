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


def parse_finite(text: str, name: str) -> float:
    """Parse a float command-line value; InputError naming ``name`` if not a finite number."""
    try:
        value = float(text)
    except ValueError:
        raise InputError(f"{name}: {text!r} is not a number") from None
    if not math.isfinite(value):
        raise InputError(f"{name}: {text!r} is not a finite number")
    return value
