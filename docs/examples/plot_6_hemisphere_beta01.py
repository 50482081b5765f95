"""
A stiff shell on the hemisphere (beta = 0.1)
============================================

The paper compares this shell with the membrane theory; here both contact-line models.
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

fig = paper_figures.make_figure("hemisphere_beta01")
plt.show()
