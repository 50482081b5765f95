"""
Varying the shell's shape gamma, from flat to prolate
=====================================================

The base scene with gamma = 0 (flat), 0.5, 1 (hemisphere), 2, 2.5 and 3 (prolate).
The paper's negative forces at small delta for gamma >= 2.5 come from its contact conditions.
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

fig = paper_figures.make_figure("gamma")
plt.show()
