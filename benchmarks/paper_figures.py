"""Regenerate the paper's figures from the model (both contact-line models).

Writes PNGs to benchmarks/figures/: each F-delta figure draws the variational
("smooth", solid) and the paper's ("paper", dashed) contact-line model.

    python benchmarks/paper_figures.py
"""

import time
from pathlib import Path

import numpy as np

import shellbvp as sb
from shellbvp.plotting import plot_fit, plot_profiles, require_matplotlib

OUT = Path(__file__).parent / "figures"


def family(ax, scenes, labels, title, delta_max=0.5):
    plt = require_matplotlib()
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, (scene, label) in enumerate(zip(scenes, labels)):
        for contact, style in (("smooth", "-"), ("paper", "--")):
            c = sb.curve(scene.replace(contact=contact), delta_max=delta_max, estimate_error=False)
            ax.plot(c.delta, c.force, style, color=colors[i % len(colors)],
                    label=f"{label}" if contact == "smooth" else None)
            print(f"  {title}: {label} {contact}: {c.summary()}", flush=True)
    ax.axhline(0, color="0.7", lw=0.5)
    ax.set_title(title + "  (solid: smooth contact, dashed: paper's)", fontsize=8)
    ax.set_xlabel(r"$\delta$ / $R_L$")
    ax.set_ylabel(r"$F$ / ($\mu H R_L$)")
    ax.legend(fontsize=7)


def main():
    plt = require_matplotlib()
    OUT.mkdir(exist_ok=True)
    t0 = time.perf_counter()
    base = sb.Scene.preset("base")

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for ax, xi in zip(axes, (0, 1)):
        betas = (1e-3, 1e-2, 1e-1)
        family(ax, [base.replace(beta=b, xi=xi) for b in betas], [f"beta = {b:g}" for b in betas],
               f"varying beta, xi = {xi}")
    fig.tight_layout()
    fig.savefig(OUT / "beta_xi.png", dpi=120)

    fig, ax = plt.subplots(figsize=(6, 4.2))
    rhos = (0.1, 0.2, 1 / 3, 0.5)
    family(ax, [base.replace(rho=r) for r in rhos], [f"rho = {r:.3g}" for r in rhos], "varying rho")
    fig.tight_layout()
    fig.savefig(OUT / "rho.png", dpi=120)

    fig, ax = plt.subplots(figsize=(6, 4.2))
    gammas = (0.0, 0.5, 1.0, 2.0, 2.5, 3.0)
    family(ax, [base.replace(gamma=g) for g in gammas], [f"gamma = {g:g}" for g in gammas], "varying gamma")
    fig.tight_layout()
    fig.savefig(OUT / "gamma.png", dpi=120)

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    alphas = (0.0, 0.1, 0.5)
    family(axes[0], [base.replace(material=sb.MooneyRivlin(a)) for a in alphas],
           [f"Mooney-Rivlin alpha = {a:g}" for a in alphas], "varying Mooney-Rivlin alpha")
    jms = (0.4, 1.0, 97.2)
    family(axes[1], [base.replace(material=sb.Gent(j)) for j in jms], [f"Gent Jm = {j:g}" for j in jms],
           "varying Gent Jm")
    fig.tight_layout()
    fig.savefig(OUT / "material.png", dpi=120)

    fig, axes = plt.subplots(1, 2, figsize=(11, 5))
    plot_profiles(sb.Scene.preset("prolate2"), [0.1, 0.3, 0.5], ax=axes[0])
    plot_profiles(sb.Scene.preset("dome"), [0.1, 0.3, 0.5], ax=axes[1])
    fig.tight_layout()
    fig.savefig(OUT / "profiles.png", dpi=120)

    fig, ax = plt.subplots(figsize=(6, 4.2))
    family(ax, [base.replace(beta=0.1)], ["hemisphere, beta = 0.1"], "shell on the hemisphere (paper: vs membrane)")
    fig.tight_layout()
    fig.savefig(OUT / "hemisphere_beta01.png", dpi=120)

    # the fit figure with synthetic Lepidium-like data
    scene = sb.Scene.preset("fit")
    R_L, mu_H, d0 = 0.3e-3, 52.0, 0.01e-3
    c = sb.curve(scene, deltas=np.linspace(0.01, 0.45, 50), estimate_error=False)
    rng = np.random.default_rng(0)
    disp = R_L * c.delta + d0
    force = mu_H * R_L * c.force * (1 + 0.02 * rng.standard_normal(c.delta.size))
    res = sb.fit(scene, disp, force, R_L=R_L)
    print(f"  synthetic fit: mu*H = {res.mu_H:.4g} N/m, 95% CI {res.mu_H_ci95}, offset {res.offset:.3g} m")
    fig, ax = plt.subplots(figsize=(6, 4.2))
    plot_fit(res, disp, force, ax=ax)
    ax.set_title(f"synthetic Lepidium-like data: mu*H = {res.mu_H:.3g} "
                 f"[{res.mu_H_ci95[0]:.3g}, {res.mu_H_ci95[1]:.3g}] N/m (true 52)", fontsize=8)
    fig.tight_layout()
    fig.savefig(OUT / "fit.png", dpi=120)
    plt.close("all")
    print(f"figures in {OUT} ({time.perf_counter() - t0:.0f} s)")


if __name__ == "__main__":
    main()
