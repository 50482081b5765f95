"""
A map of mu*H from a real AFM force map
=======================================

A JPK force map measured on a JPK CellHesion 200 (2013), read through afmformats, fitted
curve by curve, and looked at the way you should look at any map: the map of mu*H, each
pixel's rating and warnings, and one pixel's data against its fitted model.

The file is afmformats' test map ``fmt-jpk-fd_map2x2_extracted.jpk-force-map`` (MIT
licence, (c) 2019 Paul Müller; ``docs/examples/data/``): four curves, at the corners of a
10 x 10 grid over 600 um x 600 um, each pushed until the force read 1.5-1.6 nN, with a
cantilever of 0.0155 N/m.
The file does not say what was measured.  **The geometry below is assumed for illustration:**
a free-standing film 90 nm thick spanning a round opening 6 um across (rim radius R_L = 3 um),
indented by a sphere of radius 0.9 um.  A film over a hole is the shape of the package's flat
plate (``gamma = 0``), and the steep, curving rise of these curves is how a thin film
stiffens as it stretches.  With your own sample, give its own geometry.

The same on the command line (the data file is in ``docs/examples/data``)::

    shellbvp fit fmt-jpk-fd_map2x2_extracted.jpk-force-map --radius 3um --gamma 0 \\
        --indenter-radius 0.9um --thickness 90nm -o map.h5 --table map.csv
    shellbvp plot map.h5 -o map.png                 # the map of mu*H
    shellbvp plot map.h5 --pixel 0,0 -o pixel.png   # one pixel: data, model, residuals
    shellbvp plot map.h5 --pixels failed -o figs/   # one figure per pixel that failed
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import shellbvp as sb
from shellbvp.afm import read_afm, read_map_file
from shellbvp.batch import fit_map

try:
    HERE = Path(__file__).resolve().parent
except NameError:  # a notebook: run it from docs/examples, where data/ is
    HERE = Path.cwd()
MAP = HERE / "data" / "fmt-jpk-fd_map2x2_extracted.jpk-force-map"

# %%
# Reading the map
# ---------------
# ``read_afm`` gives every curve of the file with its place on the map; the displacement is
# the tip's position into the sample (height plus deflection, nanite's tip-sample
# separation), in metres, and the force in newtons.

curves = read_afm(MAP)
for c in curves:
    push = c.record.mask("loading")
    print(f"curve {c.index}: grid {c.grid}, at x = {c.position[0] * 1e6:.0f} um, "
          f"y = {c.position[1] * 1e6:.0f} um; {push.sum()} loading rows, "
          f"force up to {c.record.force[push].max() * 1e9:.2f} nN")

# %%
# The scene in lab units
# ----------------------
# The model is nondimensional: lengths over the rim radius R_L, forces over mu*H*R_L.  The
# lab's lengths become the scene's numbers by dividing by R_L; the thickness sets the
# bending stiffness of a 3D plate (beta = eps^2/3) and lets the fit report the modulus
# mu = mu*H / H.

R_L = 3e-6                       # rim radius (m): an opening 6 um across
scene = sb.Scene(gamma=0.0,      # flat: a film spanning the opening
                 rho=0.9e-6 / R_L,          # indenter radius over R_L
                 thickness=90e-9 / R_L)     # H / R_L = 0.03
print(scene.describe(R_L))

# %%
# The fit
# -------
# ``fit_map`` fits the loading segment of every curve with this scene.  Curves of
# comparable depth share one model curve (kept in the code cache, so a second run computes
# none); each curve gets its own mu*H, contact point and force baseline.

fm = fit_map(scene, curves, R_L=R_L)
print(fm.summary())

# %%
# Each pixel's rating and warnings
# --------------------------------
# A pixel's status is ``ok`` (the fit passed its checks), ``failed`` (it ran but failed
# them) or ``error``; its quality is ``good``, ``fair`` or ``poor`` by written rules
# (``shellbvp.fit_checks.QUALITY_RULES``), and its warnings say what the checks found
# (``shellbvp.fit_checks.FIT_WARNINGS``).

for c, row in zip(curves, fm.rows):
    r = row.result
    lo, hi = r.mu_H_ci95
    mu = r.derived["mu"]
    print(f"pixel {c.grid}: {row.status:6s} {r.quality:4s} mu*H = {r.mu_H * 1e3:.4g} mN/m "
          f"[{lo * 1e3:.4g}, {hi * 1e3:.4g}], mu = {mu.value / 1e6:.3g} MPa; "
          f"warnings: {', '.join(r.warning_codes) or 'none'}")
for code, (where, text) in fm.warning_counts().items():
    print(f"\n{code} in {len(where)} pixels, e.g. {where[0]}: {text}")

# %%
# Read the ratings before the numbers.  On this file every pixel is rated poor (the
# summary above counts them): where the tip touches, the data leave the baseline well
# before the model's force starts to rise (``contact_misfit`` where the
# misfit is large), the residuals' signs run in long runs (``residual_runs``), and on three
# pixels a fit with another noise model gives another mu*H (status ``failed``,
# ``weights_disagree``).  Their 95 % intervals then do not say how well mu*H is known: the
# assumed film does not describe these curves well enough, and the spread of mu*H over the
# map (more than a factor 20) is no measurement of the sample's variation.
#
# The map of mu*H
# ---------------
# Only pixels whose fit passed its checks are drawn (one of four here); the others are
# blank, as are the 96 cells where nothing was measured.  Beside it, each pixel's status and
# rating.

fig, (ax, ax_status) = plt.subplots(1, 2, figsize=(10, 4.2))
fm.plot(ax=ax)
codes = fm.status_image().astype(float)
codes[codes < 0] = np.nan                         # no curve
x, y = fm.axes()
half = np.ptp(x) / (len(x) - 1) / 2               # half a cell
extent = ((x[0] - half) * 1e6, (x[-1] + half) * 1e6, (y[0] - half) * 1e6, (y[-1] + half) * 1e6)
ax_status.imshow(codes, origin="lower", extent=extent, cmap="RdYlGn_r", vmin=0, vmax=2)
for c, row in zip(curves, fm.rows):
    ax_status.annotate(f"{c.grid}\n{row.status}\n{row.result.quality}", (x[c.grid[0]] * 1e6, y[c.grid[1]] * 1e6),
                       ha="center", va="center", fontsize=7)
ax_status.set(title="status and rating of each pixel", xlabel="x (um)", ylabel="y (um)")
fig.tight_layout()

# %%
# The map file and one pixel's fit
# --------------------------------
# ``to_hdf5`` writes the map as NeXus: the images, one row per curve (mu*H, interval,
# status, rating, warnings) and each curve's fitted rows with the model at them (at most
# 1000 rows a curve).  ``read_map_file`` reads it back, and ``plot_pixel`` draws one pixel
# from the file alone (``shellbvp plot map.h5 --pixel 0,9``): the data and the fitted model
# on the left, the same near the contact on the right (against the depth beyond the fitted
# contact point), the residuals below.  Pixel (0, 9) is the one on the map:

out = Path(tempfile.mkdtemp()) / "map.h5"
fm.to_hdf5(out)
mf = read_map_file(out)
print("\n".join(mf.summary_lines()))
print(mf.pixel(0, 9).line())
mf.plot_pixel(0, 9)

# %%
# Its fit passed the checks, yet the figure shows why it is rated poor: the data leave the
# baseline about a micrometre before the fitted contact point (left), the model starts at
# it and then rises faster (right), and the residuals near the contact are systematic.
#
# A failed pixel is drawn the same way, with the reason it failed under it.  Pixel (0, 0)
# follows the film's curve more closely, but its two noise models disagree:

failed = mf.pixels("failed")
print("failed:", failed)
mf.plot_pixel(*failed[0])

# %%
# Things to try on such a map: a fitting range where the model follows the data
# (``max_depth=``, ``max_force=``; ``--max-depth``, ``--force-max``), a linear baseline
# (``baseline="linear"``), and above all the sample's real geometry.  To look at every pixel
# that failed: ``shellbvp plot map.h5 --pixels failed -o figs/`` (one PNG each, at most 100
# unless ``--max-figures`` says more).

plt.show()
