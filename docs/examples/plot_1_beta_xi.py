"""
Varying the bending stiffness beta, with xi = 0 and xi = 1
==========================================================

The base scene (hemisphere, rho = 0.2, Mooney-Rivlin alpha = 0.1) with beta = 1e-3, 1e-2 and 0.1.
With the first approximation (xi = 0, left) and the full generalised tensions (xi = 1, right).
The paper's contact conditions (dashed) give negative forces at small delta with xi = 0;
the variational ones (solid) never do (see :doc:`/model`).
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

fig = paper_figures.make_figure("beta_xi")
plt.show()
