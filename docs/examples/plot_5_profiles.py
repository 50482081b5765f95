"""
Deformed profiles of a prolate shell and a dome
===============================================

The deformed meridians at delta = 0.1, 0.3, 0.5 for the prolate spheroid (gamma = 2, left)
and the dome (gamma = -1, right), with the indenter and the undeformed shell dashed.
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

fig = paper_figures.make_figure("profiles")
plt.show()
