"""Regenerate the paper's figures from the model (both contact-line models).

Writes PNGs to benchmarks/figures/: each F-delta figure draws the variational
("smooth", solid) and the paper's ("paper", dashed) contact-line model.

    python benchmarks/paper_figures.py [--only beta_xi,rho,gamma,material,profiles,hemisphere_beta01,fit] [--out-dir DIR]

The scenes of each figure are in FAMILIES (benchmarks/fit_models.py checks the
paper's claims on the same scenes).
"""

import argparse
import time
from pathlib import Path

import numpy as np

import shellbvp as sb
from shellbvp.plotting import plot_fit, plot_profiles, require_matplotlib

from checkout import add_output_args, figures_dir  # benchmarks/ is on sys.path

OUT = Path(__file__).parent / "figures"
FIGURES = ("beta_xi", "rho", "gamma", "material", "profiles", "hemisphere_beta01", "fit")
DELTA_MAX = 0.5


def families():
    """Panel name -> [(scene, label)]: the curves of each F-delta panel."""
    base = sb.Scene.preset("base")
    betas, rhos, gammas = (1e-3, 1e-2, 1e-1), (0.1, 0.2, 1 / 3, 0.5), (0.0, 0.5, 1.0, 2.0, 2.5, 3.0)
    alphas, jms = (0.0, 0.1, 0.5), (0.4, 1.0, 97.2)
    return {
        "beta_xi0": [(base.replace(beta=b, xi=0), f"beta = {b:g}") for b in betas],
        "beta_xi1": [(base.replace(beta=b, xi=1), f"beta = {b:g}") for b in betas],
        "rho": [(base.replace(rho=r), f"rho = {r:.3g}") for r in rhos],
        "gamma": [(base.replace(gamma=g), f"gamma = {g:g}") for g in gammas],
        "alpha": [(base.replace(material=sb.MooneyRivlin(a)), f"Mooney-Rivlin alpha = {a:g}") for a in alphas],
        "gent": [(base.replace(material=sb.Gent(j)), f"Gent Jm = {j:g}") for j in jms],
        "hemisphere_beta01": [(base.replace(beta=0.1), "hemisphere, beta = 0.1")],
    }


def model_curve(scene, contact, delta_max=DELTA_MAX):
    """The curve drawn for a scene and contact model (adaptive, to delta_max)."""
    return sb.curve(scene.replace(contact=contact), delta_max=delta_max, estimate_error=False)


def family(ax, members, title, delta_max=DELTA_MAX):
    plt = require_matplotlib()
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, (scene, label) in enumerate(members):
        for contact, style in (("smooth", "-"), ("paper", "--")):
            c = model_curve(scene, contact, delta_max)
            ax.plot(c.delta, c.force, style, color=colors[i % len(colors)],
                    label=f"{label}" if contact == "smooth" else None)
            print(f"  {title}: {label} {contact}: {c.summary()}", flush=True)
    ax.axhline(0, color="0.7", lw=0.5)
    ax.set_title(title + "  (solid: smooth contact, dashed: paper's)", fontsize=8)
    ax.set_xlabel(r"$\delta$ / $R_L$")
    ax.set_ylabel(r"$F$ / ($\mu H R_L$)")
    ax.legend(fontsize=7)


def fit_figure(plt):
    """The fit figure with synthetic Lepidium-like data (seed 0, 50 points, 2 % proportional noise)."""
    scene = sb.Scene.preset("fit")
    R_L, mu_H, d0 = 0.3e-3, 52.0, 0.01e-3
    c = sb.curve(scene, deltas=np.linspace(0.01, 0.45, 50), estimate_error=False)
    rng = np.random.default_rng(0)
    disp = R_L * c.delta + d0
    force = mu_H * R_L * c.force * (1 + 0.02 * rng.standard_normal(c.delta.size))
    res = sb.fit(scene, disp, force, R_L=R_L)
    print(f"  synthetic fit: mu*H = {res.mu_H:.4g} N/m, 95% CI {res.mu_H_ci95}, offset {res.offset:.3g} m, "
          f"{res.weights} weights")
    fig, ax = plt.subplots(figsize=(6, 4.2))
    plot_fit(res, disp, force, ax=ax)
    ax.set_title(f"synthetic Lepidium-like data: mu*H = {res.mu_H:.3g} "
                 f"[{res.mu_H_ci95[0]:.3g}, {res.mu_H_ci95[1]:.3g}] N/m (true 52; {res.weights} weights)",
                 fontsize=8)
    fig.tight_layout()
    return fig


def make_figure(name, fam=None):
    """The figure ``name`` (one of FIGURES) as a matplotlib Figure; also used by the docs' gallery."""
    plt = require_matplotlib()
    fam = families() if fam is None else fam
    if name == "beta_xi":
        fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
        for ax, xi in zip(axes, (0, 1)):
            family(ax, fam[f"beta_xi{xi}"], f"varying beta, xi = {xi}")
    elif name == "rho":
        fig, ax = plt.subplots(figsize=(6, 4.2))
        family(ax, fam["rho"], "varying rho")
    elif name == "gamma":
        fig, ax = plt.subplots(figsize=(6, 4.2))
        family(ax, fam["gamma"], "varying gamma")
    elif name == "material":
        fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
        family(axes[0], fam["alpha"], "varying Mooney-Rivlin alpha")
        family(axes[1], fam["gent"], "varying Gent Jm")
    elif name == "profiles":
        fig, axes = plt.subplots(1, 2, figsize=(11, 5))
        plot_profiles(sb.Scene.preset("prolate2"), [0.1, 0.3, 0.5], ax=axes[0])
        plot_profiles(sb.Scene.preset("dome"), [0.1, 0.3, 0.5], ax=axes[1])
    elif name == "hemisphere_beta01":
        fig, ax = plt.subplots(figsize=(6, 4.2))
        family(ax, fam["hemisphere_beta01"], "shell on the hemisphere (paper: vs membrane)")
    elif name == "fit":
        return fit_figure(plt)
    else:
        raise ValueError(f"unknown figure {name!r}; choose from {FIGURES}")
    fig.tight_layout()
    return fig


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", help="comma-separated figures: " + ",".join(FIGURES))
    add_output_args(ap)
    args = ap.parse_args()
    global OUT
    OUT = figures_dir(args.out_dir)
    only = set(FIGURES if not args.only else args.only.split(","))
    if only - set(FIGURES):
        ap.error(f"unknown figures {sorted(only - set(FIGURES))}; choose from {FIGURES}")
    plt = require_matplotlib()
    OUT.mkdir(exist_ok=True)
    t0 = time.perf_counter()
    fam = families()
    for name in FIGURES:
        if name in only:
            make_figure(name, fam).savefig(OUT / f"{name}.png", dpi=120)
    plt.close("all")
    print(f"figures in {OUT} ({time.perf_counter() - t0:.0f} s)")


if __name__ == "__main__":
    main()
