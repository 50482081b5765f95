"""Figures with matplotlib (optional extra: ``pip install 'shellbvp[plot]'``).

* :func:`plot_curves` -- force against displacement, several curves overlaid;
* :func:`plot_profiles` -- deformed meridians r(z) at chosen depths with the
  indenter and the undeformed shell dashed (as in the paper's figures);
* :func:`plot_fit` -- measured data, the fitted model and its 95 % band.
"""

from __future__ import annotations

import numpy as np

__all__ = ["plot_curves", "plot_profiles", "plot_fit", "require_matplotlib", "scene_label"]


def require_matplotlib():
    """Import pyplot on the Agg backend, or say how to install it."""
    try:
        import matplotlib

        matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt
    except ImportError:
        raise ValueError("plotting needs matplotlib: pip install 'shellbvp[plot]'") from None
    return plt


def scene_label(scene) -> str:
    m = scene.material
    mat = {"mooney-rivlin": lambda: f"MR {m.alpha:g}", "neo-hookean": lambda: "NH",
           "gent": lambda: f"Gent {m.Jm:g}", "user": lambda: "user W"}[m.family]()
    return (f"gamma={scene.gamma:g} rho={scene.rho:.3g} beta={scene.beta:g} {mat} xi={scene.xi} "
            f"{scene.contact}")


def plot_curves(curves, ax=None, labels=None, mark_invalid=True):
    """F against delta for each curve; invalid states (flags) drawn hollow."""
    plt = require_matplotlib()
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 4.5))
    for i, c in enumerate(curves):
        label = labels[i] if labels else scene_label(c.scene)
        (line,) = ax.plot(c.delta, c.force, "-", label=label)
        if mark_invalid and len(c):
            bad = ~np.asarray(c.valid, bool)
            ax.plot(c.delta[bad], c.force[bad], "o", mfc="none", ms=4, color=line.get_color())
    ax.axhline(0, color="0.7", lw=0.5)
    ax.set_xlabel(r"pole displacement $\delta$ / $R_L$")
    ax.set_ylabel(r"force $F$ / ($\mu H R_L$)")
    ax.legend(fontsize=7)
    return ax


def plot_profiles(scene, deltas, ax=None, solutions=None):
    """Deformed meridians at the given depths, the indenter and the undeformed shell."""
    plt = require_matplotlib()
    from .state import solve

    if ax is None:
        _, ax = plt.subplots(figsize=(5, 5))
    mod = scene.model()
    par = scene.parameters(mod)
    S = np.linspace(0, scene.shell_length, 200)
    ref = mod.reference_shell(np.maximum(S, 1e-9), par)
    for sign in (1, -1):
        ax.plot(sign * ref["R"], ref["Z"], "k--", lw=0.8)
    sol = None
    sols = solutions or []
    if not sols:
        for d in sorted(deltas):
            sol = solve(scene, delta=d, guess=sol if sol is not None and sol.get("topology") == "cap" else None,
                        estimate_error=False)
            sols.append(sol)
    om = np.linspace(0, scene.tip_omega_max, 100)
    tip = mod.tip_shape(om, par)
    for s in sols:
        if not s.success:
            continue
        p = s.profile()
        (line,) = ax.plot(p["r"], p["z"], "-", label=f"delta = {s.delta:g}")
        ax.plot(-p["r"], p["z"], "-", color=line.get_color())
        r_t, z_t = scene.rho * tip["A"], s.z_tip + scene.rho * tip["B"]
        top = z_t[-1] + 0.3
        ax.plot(np.r_[-r_t[::-1], r_t], np.r_[z_t[::-1], z_t], ":", color=line.get_color(), lw=1)
        ax.plot([r_t[-1], r_t[-1]], [z_t[-1], top], ":", color=line.get_color(), lw=1)
        ax.plot([-r_t[-1], -r_t[-1]], [z_t[-1], top], ":", color=line.get_color(), lw=1)
    ax.set_aspect("equal")
    ax.set_xlabel("r / R_L")
    ax.set_ylabel("z / R_L")
    ax.set_title(scene_label(scene), fontsize=7)
    ax.legend(fontsize=7)
    return ax


def plot_fit(result, displacement, force, ax=None):
    """Measured data (mm, mN), the fitted model and the band of mu*H's 95 % interval."""
    plt = require_matplotlib()
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 4.5))
    d = np.asarray(displacement) * 1e3
    ax.plot(d, np.asarray(force) * 1e3, "k.", ms=3, label="data")
    x = np.linspace(max(result.offset, 0), np.max(displacement), 300)
    ax.plot(x * 1e3, result.model_force(x) * 1e3, "-", label=f"model, mu*H = {result.mu_H:.3g} N/m")
    lo = result._model(x, result.mu_H_ci95[0], result.offset) * 1e3
    hi = result._model(x, result.mu_H_ci95[1], result.offset) * 1e3
    ax.fill_between(x * 1e3, lo, hi, alpha=0.3, label="95% interval of mu*H")
    ax.set_xlabel("displacement (mm)")
    ax.set_ylabel("force (mN)")
    ax.legend(fontsize=8)
    return ax
