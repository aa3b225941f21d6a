"""``trajectory.csv``: header, one row per sample, every value read back bit for bit."""

from __future__ import annotations

import io

import numpy as np
import pytest

from lynxplan.exceptions import ShapeError
from lynxplan.scenarios.outputs import csv_rows, write_trajectory_csv

#: Values whose shortest decimal forms are awkward: subnormals, extremes, exponents, -0.0.
AWKWARD = [0.0, -0.0, 0.1, 1 / 3, 1e-7, 1e16, 1e20, -2.5e-308, 5e-324, 1.7976931348623157e308]
AWKWARD += [123456789.123, -1e-300]


def _bits(values: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(values, dtype=np.float64).view(np.int64)


def test_every_value_reads_back_to_the_same_float() -> None:
    rng = np.random.default_rng(11)
    random_bits = rng.integers(0, 2**63 - 1, size=(4000, 6), dtype=np.int64).view(np.float64)
    finite = random_bits[np.isfinite(random_bits).all(axis=1)]
    table = np.vstack([finite, np.reshape(AWKWARD, (2, 6)), rng.normal(size=(500, 6)) * 1e-3])
    table = np.vstack([table, -table])
    text = csv_rows(table)
    assert text.count("\n") == len(table)
    reloaded = np.loadtxt(io.StringIO(text), delimiter=",")
    np.testing.assert_array_equal(_bits(reloaded), _bits(table))


def test_non_finite_values_are_written_as_nan_and_inf() -> None:
    table = np.array([[0.5, np.nan], [np.inf, -np.inf]])
    text = csv_rows(table)
    assert text == "0.5,nan\ninf,-inf\n"
    np.testing.assert_array_equal(np.loadtxt(io.StringIO(text), delimiter=","), table)


def test_an_empty_table_has_no_rows() -> None:
    assert csv_rows(np.empty((0, 4))) == ""


def test_a_table_must_be_two_dimensional() -> None:
    with pytest.raises(ShapeError, match=r"table"):
        csv_rows(np.zeros(3))


def test_trajectory_csv_header_and_columns(tmp_path) -> None:
    rng = np.random.default_rng(3)
    t = np.arange(7) / 1000.0
    q, qd, qdd, xyz = (rng.normal(size=(7, n)) for n in (2, 2, 2, 3))
    path = tmp_path / "trajectory.csv"
    write_trajectory_csv(path, t, q, qd, qdd, xyz)
    lines = path.read_text(encoding="ascii").splitlines()
    assert lines[0] == "t,q1,q2,qd1,qd2,qdd1,qdd2,x,y,z"
    assert len(lines) == 8
    table = np.loadtxt(path, delimiter=",", skiprows=1)
    np.testing.assert_array_equal(table, np.hstack([t[:, None], q, qd, qdd, xyz]))
