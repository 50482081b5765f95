"""
Varying the material: Mooney-Rivlin alpha and Gent Jm
=====================================================

Left: Mooney-Rivlin alpha = 0 (neo-Hookean), 0.1, 0.5.  Right: Gent with Jm = 0.4
(stiff tissue), 1 and 97.2 (rubber): the Gent curves stiffen as I1 - 3 approaches Jm.
"""

import sys
from pathlib import Path

import matplotlib.pyplot as plt

# benchmarks/ is not in the installed package: found from this file (docs/examples/)
try:
    HERE = Path(__file__).resolve().parent
except NameError:  # pasted into an interactive session
    HERE = Path.cwd() / "docs" / "examples"   # from the repository root
sys.path.insert(0, str(HERE.parents[1] / "benchmarks"))

import paper_figures  # noqa: E402

fig = paper_figures.make_figure("material")
plt.show()
