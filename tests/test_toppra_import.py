"""toppra loads without importing matplotlib; its plotting stand-in still reaches pyplot."""

from __future__ import annotations

import subprocess
import sys


def test_toppra_import_defers_pyplot() -> None:
    code = (
        "import sys\n"
        "from lynxplan._toppra import import_toppra\n"
        "toppra = import_toppra()\n"
        "import toppra.algorithm.algorithm as algorithm\n"
        "print('matplotlib' in sys.modules, callable(toppra.algorithm.TOPPRA))\n"
        "import matplotlib\n"
        "matplotlib.use('Agg')\n"
        "print(algorithm.plt.plot.__module__)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "True", "matplotlib.pyplot"]
