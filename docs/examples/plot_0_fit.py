"""
Fitting mu*H to a measured curve
================================

The synthetic Lepidium-like record shipped with the package
(``shellbvp/data/lepidium_synthetic.csv``: preset ``fit``, rim radius
R_L = 0.3 mm, mu*H = 52 N/m, contact 10 um into the record, 2 % proportional
noise, in mm and mN) fitted with the variational contact model.  The fit finds
mu*H and the contact point; the band is mu*H's 95 % interval.

The same on the command line::

    shellbvp fit --example --preset fit --radius 0.3mm -o fit.h5
    shellbvp plot fit.h5 -o fit.png
"""

import matplotlib.pyplot as plt

import shellbvp as sb
from shellbvp.fitting import example_data_path
from shellbvp.plotting import plot_fit

scene = sb.Scene.preset("fit")   # gamma 2.5, rho 1/3, beta 0.01, Mooney-Rivlin 0.1
d, F = sb.read_force_csv(example_data_path())   # SI: m and N (the file: mm, mN)
res = sb.fit(scene, d, F, R_L=0.3e-3)           # about 3 s: one model curve
lo, hi = res.mu_H_ci95
print(f"mu*H = {res.mu_H:.4g} N/m, 95 % CI [{lo:.4g}, {hi:.4g}]")
print(f"contact point {res.offset * 1e3:.4g} mm, "
      f"rms residual {res.residual_rms * 1e3:.3g} mN")

fig, ax = plt.subplots(figsize=(6, 4.2))
plot_fit(res, d, F, ax=ax)
ax.set_title("synthetic Lepidium-like record (true mu*H = 52 N/m)",
             fontsize=9)
fig.tight_layout()
plt.show()
