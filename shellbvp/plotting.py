"""Figures with matplotlib (optional extra: ``pip install 'shellbvp[plot]'``).

* :func:`plot_curves` -- force against displacement, several curves overlaid;
* :func:`plot_profiles` -- deformed meridians r(z) at chosen depths with the
  indenter and the undeformed shell dashed (as in the paper's figures);
* :func:`plot_fit` -- measured data, the fitted model and its 95 % band;
* :func:`plot_map_pixel` -- one pixel of a force map: its data, model and residuals.
"""

from __future__ import annotations

import numpy as np

from .configurations import is_single_cap
from .textdata import printable
from .fitrecord import PARAMETER_UNITS
from .fitting import diagnostics_lines
from .fitting.apparent import apparent_modulus
from .paths import atomic_file
from .state import solve
from .thickness import model_error_line
from .units import unit_factor

__all__ = ["plot_curves", "plot_profiles", "plot_fit", "plot_fit_record", "plot_map_pixel", "map_pixel_notes", "plot_apparent_modulus", "record_apparent_modulus", "fit_report", "fit_summary_lines",
           "require_matplotlib", "scene_label", "save_figure"]


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
    return (f"gamma={scene.gamma:g} rho={scene.rho:.3g} beta={scene.beta:g} {scene.material.legend()} xi={scene.xi} "
            f"{scene.contact}" + (f" p={scene.pressure:g}" if scene.pressure else ""))


def plot_curves(curves, ax=None, labels=None, mark_invalid=True):
    """F against delta for each curve; invalid states (flags) drawn hollow.  When every curve
    carries its lab scales (a file written with ``units=``: SI columns), in mm and mN."""
    plt = require_matplotlib()
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 4.5))
    si = bool(curves) and all(getattr(c, "units", None) for c in curves)
    for i, c in enumerate(curves):
        label = labels[i] if labels else scene_label(c.scene)
        sx, sy = (c.units["R_L"] * 1e3, c.units["mu_H"] * c.units["R_L"] * 1e3) if si else (1.0, 1.0)
        (line,) = ax.plot(sx * c.delta, sy * c.force, "-", label=label)
        if mark_invalid and len(c):
            bad = ~np.asarray(c.valid, bool)
            ax.plot(sx * c.delta[bad], sy * c.force[bad], "o", mfc="none", ms=4, color=line.get_color())
        first = getattr(c, "first_instability", None)
        if first is not None:  # where the axisymmetric branch stops being stable
            ax.plot(sx * first.delta, sy * first.force, "x", ms=8, mew=1.5, color=line.get_color(),
                    label=f"unstable from here (n = {first.mode})")
    ax.axhline(0, color="0.7", lw=0.5)
    if si:
        ax.set_xlabel("pole displacement (mm)")
        ax.set_ylabel("force (mN)")
    else:
        ax.set_xlabel(r"pole displacement $\delta$ / $R_L$")
        ax.set_ylabel(r"force $F$ / ($\mu H R_L$)")
    ax.legend(fontsize=7)
    return ax


def plot_profiles(scene, deltas, ax=None, solutions=None):
    """Deformed meridians at the given depths, the indenter and the undeformed shell."""
    plt = require_matplotlib()

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
            sol = solve(scene, delta=d, guess=sol if sol is not None and is_single_cap(sol) else None,
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
    ax.set_title(printable(scene_label(scene)), fontsize=7)
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
    lo = result.model_force(x, mu_H=result.mu_H_ci95[0]) * 1e3
    hi = result.model_force(x, mu_H=result.mu_H_ci95[1]) * 1e3
    ax.fill_between(x * 1e3, lo, hi, alpha=0.3, label="95% interval of mu*H")
    ax.set_xlabel("displacement (mm)")
    ax.set_ylabel("force (mN)")
    ax.legend(fontsize=8)
    return ax


def save_figure(fig, path, dpi=150):
    """Save ``fig`` atomically (a temporary file in the same directory, then renamed): a
    reader never sees half a figure and an earlier one stays whole if drawing fails.
    The format follows the name's suffix (png, pdf, svg, ...)."""
    from pathlib import Path

    path = Path(path)
    fmt = path.suffix.lstrip(".").lower() or "png"
    with atomic_file(path) as tmp:
        fig.savefig(tmp, dpi=dpi, format=fmt)
    return path


def _si_axis(ax, which, unit):
    """SI units with engineering prefixes on an axis (``10 µm``, ``2 mN``)."""
    from matplotlib.ticker import EngFormatter

    (ax.xaxis if which == "x" else ax.yaxis).set_major_formatter(EngFormatter(unit=unit))


def plot_fit_record(record, axes=None):
    """Data, model and residuals of a fit file (:func:`shellbvp.fitrecord.read_fit`), in SI units.

    The rows fitted are drawn filled, the others (the retraction, a hold, ...) hollow and
    grey; the model over the fitted depth range; below, the residuals (model - data) of
    the rows fitted.  The legend gives mu*H and its 95 % interval.

    Parameters
    ----------
    record : FitRecord
    axes : (Axes, Axes), optional
        The data and residual axes (default: a new figure with both).

    Returns
    -------
    (Axes, Axes)
    """
    plt = require_matplotlib()
    if axes is None:
        fig, axes = plt.subplots(2, 1, figsize=(6.4, 6), sharex=True, gridspec_kw={"height_ratios": [3, 1]})
    ax, axr = axes
    data, p = record.data, record.parameters
    used = data["used"]
    d, f = data["displacement"], data["force"]
    ax.plot(d[~used], f[~used], "o", mfc="none", mec="0.6", ms=3, label="not fitted")
    ax.plot(d[used], f[used], "k.", ms=3, label=f"data ({record.settings['segment']}, {int(used.sum())} rows)")
    lo, hi = record.intervals.get("mu_H", (np.nan, np.nan))
    m = record.model
    top = min(np.max(d[used]) if used.any() else np.max(d), np.max(m["displacement"]))
    x = np.linspace(min(np.min(d[used]) if used.any() else np.min(d), p["offset"]), top, 400)
    base = p["baseline"] + p["baseline_slope"] * (x - p["offset"])
    yv = np.interp(x, m["displacement"], m["force"])
    yv = np.where(x < p["offset"], base, yv)
    ax.plot(x, yv, "-", color="C3",
            label=f"model: mu*H = {p['mu_H']:.4g} N/m, 95% CI [{lo:.4g}, {hi:.4g}]")
    if record.settings.get("baseline_model", "none") != "none":
        ax.axvline(p["offset"], color="0.5", lw=0.6, ls=":", label="contact point")
    _si_axis(ax, "y", "N")
    ax.set_ylabel("force")
    ax.set_title(f"{printable(record.source['file_name'].split('/')[-1])}: {'fit' if record.success else 'FAILED fit'}",
                 fontsize=9)
    ax.legend(fontsize=7)
    axr.axhline(0, color="0.6", lw=0.6)
    axr.plot(d[used], data["residual"][used], "k.", ms=3)
    _si_axis(axr, "y", "N")
    _si_axis(axr, "x", "m")
    axr.set_ylabel("model - data")
    axr.set_xlabel("displacement")
    return ax, axr


def plot_map_pixel(pixel, axes=None):
    """One pixel of a force map (:class:`shellbvp.map_pixels.MapPixel`) in SI units: on the left
    its fitted rows and the fitted model at them, on the right the same around the contact
    (from one contact depth before the fitted contact point to the deepest row), below each the
    residuals (model - data); the right's abscissa is the depth beyond the fitted contact point
    (the displacement where there is no fit).  The title gives the pixel, the fit's status and rating, the legend
    mu*H and its 95 % interval; :func:`map_pixel_notes` the message and warnings.

    Parameters
    ----------
    pixel : MapPixel
        With its rows (``displacement`` not None).
    axes : 2 x 2 array of Axes, optional
        ``[[data, data near contact], [residuals, residuals near contact]]`` (default: a new figure).

    Returns
    -------
    ndarray of Axes, shape (2, 2)
    """
    plt = require_matplotlib()
    from matplotlib.ticker import MaxNLocator

    if axes is None:
        _, axes = plt.subplots(2, 2, figsize=(10, 6.2), sharex="col", gridspec_kw={"height_ratios": [3, 1]})
    axes = np.asarray(axes).reshape(2, 2)
    d, f, m = pixel.displacement, pixel.force, pixel.model_force
    order = np.argsort(d, kind="stable")
    fitted = np.isfinite(m)
    shown = f"{d.size} of {pixel.rows_fitted} rows" if d.size < (pixel.rows_fitted or 0) else f"{d.size} rows"
    depth = np.max(d) - pixel.offset if np.isfinite(pixel.offset) else np.nan
    near = (d >= pixel.offset - depth) if np.isfinite(depth) and depth > 0 else np.ones(d.size, bool)
    zero = pixel.offset if np.isfinite(depth) else 0.0  # the right: depth beyond the fitted contact point
    for col, (keep, x) in enumerate(((np.ones(d.size, bool), d), (near, d - zero))):
        ax, axr = axes[0, col], axes[1, col]
        ax.plot(x[keep], f[keep], "k.", ms=2, label=f"data ({shown} fitted)" if col == 0 else None)
        line = order[keep[order] & fitted[order]]
        if line.size:
            lo, hi = pixel.mu_H_ci95
            ax.plot(x[line], m[line], "-", color="C3",
                    label=f"model: mu*H = {pixel.mu_H:.4g} N/m, 95% CI [{lo:.4g}, {hi:.4g}]" if col == 0 else None)
            ax.axvline(pixel.offset - (zero if col else 0.0), color="0.5", lw=0.6, ls=":",
                       label="contact point" if col == 0 else None)
            axr.axhline(0, color="0.6", lw=0.6)
            axr.plot(x[keep & fitted], (m - f)[keep & fitted], "k.", ms=2)
        _si_axis(ax, "y", "N")
        _si_axis(axr, "y", "N")
        _si_axis(axr, "x", "m")
        axr.xaxis.set_major_locator(MaxNLocator(5))
    axes[1, 0].set_xlabel("displacement")
    axes[1, 1].set_xlabel("depth beyond the fitted contact point" if np.isfinite(depth) else "displacement")
    axes[0, 0].set_ylabel("force")
    axes[1, 0].set_ylabel("model - data")
    axes[0, 0].legend(fontsize=7, loc="upper left")
    verdict = {"ok": "fit", "failed": "FAILED fit", "error": "no fit (error)"}.get(pixel.status, pixel.status)
    rating = f", quality {pixel.quality}" if pixel.quality else ""
    axes[0, 0].figure.suptitle(f"{printable(str(pixel.source).split('/')[-1])}: pixel {pixel.grid} (curve "
                               f"{pixel.index}): {verdict}{rating}", fontsize=10)
    return axes


def map_pixel_notes(pixel, width=120) -> str:
    """The lines under a pixel's figure: its fit's message (where it did not succeed) and the kinds
    of its warnings, wrapped to ``width`` characters (text from the file escaped)."""
    import textwrap

    lines = [] if pixel.status == "ok" else [f"{pixel.status}: {printable(pixel.message)}"]
    if pixel.warning_codes:
        lines.append("warnings: " + ", ".join(printable(c) for c in pixel.warning_codes)
                     + " (shellbvp.fit_checks.FIT_WARNINGS)")
    return "\n".join(textwrap.fill(ln, width) for ln in lines)


def record_apparent_modulus(record):
    """E(delta) of a fit file's fitted rows (:func:`shellbvp.fitting.apparent.apparent_modulus`), the
    model from its curve (linear between the curve's depths), the thickness given or fitted."""
    p, m, used = record.parameters, record.model, record.data["used"]
    R_L, offset = p["R_L"], p["offset"]
    delta, F = np.asarray(m["delta"], float), np.asarray(m["F"], float)
    return apparent_modulus(record.data["displacement"][used], record.data["force"][used],
                            lambda x: R_L * np.interp((x - offset) / R_L, delta, F, right=np.nan),
                            offset=offset, baseline=p["baseline"], baseline_slope=p["baseline_slope"],
                            thickness=_thickness(record))


def _thickness(record):
    """The shell's thickness H (m) of a fit file: fitted, else the scene's, else None."""
    fitted = record.parameters.get("thickness", np.nan)
    if np.isfinite(fitted):
        return float(fitted)
    return None if record.scene.thickness is None else record.scene.thickness * record.parameters["R_L"]


def plot_apparent_modulus(record, ax):
    """E(delta) of a fit file on ``ax`` (mu*H(delta) without a thickness): each fitted point's
    apparent modulus against its depth beyond the contact point, the fitted value and its 95 %
    interval as a band.  Flat: the model follows the data's shape."""
    am = record_apparent_modulus(record)
    p = record.parameters
    lo, hi = record.intervals.get("mu_H", (np.nan, np.nan))
    H = _thickness(record)
    scale, unit, name = (1.0, "N/m", "mu*H") if H is None else (3.0 / H, "Pa", "E")
    values = am.mu_H if am.E is None else am.E
    ax.plot(am.depth, values, "k.", ms=2, label=f"apparent {name}: the model through each point alone")
    ax.axhline(scale * p["mu_H"], color="C3", lw=1, label=f"fitted {name}")
    if np.isfinite(lo) and np.isfinite(hi):
        ax.axhspan(scale * lo, scale * hi, color="C3", alpha=0.2, lw=0)
    if values.size:
        a, b = np.nanpercentile(values, [2, 98])
        pad = 0.1 * (b - a) or 0.1 * abs(b) or 1.0
        ax.set_ylim(min(a, scale * p["mu_H"]) - pad, max(b, scale * p["mu_H"]) + pad)
    _si_axis(ax, "x", "m")
    _si_axis(ax, "y", unit)
    ax.set_xlabel("depth beyond the contact point")
    ax.set_ylabel(f"{name}(depth)")
    ax.legend(fontsize=6, loc="best")
    return ax


def _display(record):
    """``show(value, si_unit) -> (number text, unit)``: lengths and forces in the units of the data's
    file (as the fit command prints them), everything else as stored."""
    def factor(unit, kind):
        try:
            return unit_factor(unit, kind), unit
        except (ValueError, TypeError, KeyError):
            return None

    units = record.source["units"] if isinstance(record.source["units"], dict) else {}
    shown = {si: factor(units[key], kind) if key in units else None
             for si, key, kind in (("m", "displacement", "length"), ("N", "force", "force"))}

    def show(value, si_unit):
        found = shown.get(si_unit)
        if found is None:
            return f"{value:.5g}", "" if si_unit == "1" else si_unit
        f, unit = found
        return f"{value / f:.5g}", unit

    return show


#: A fit's model in words (``FitRecord.settings["model"]``).
_MODEL_WORDS = {("shell", False): "the shell model (its mid-surface pole's displacement as the data's)",
                ("solid", False): "the 3D solid (its indenter's displacement from first touch as the data's)",
                ("shell", True): "the shell model (its mid-surface poles' approach as the data's)",
                ("solid", True): "the 3D solid (its indenters' approach from first touch as the data's)"}


def fit_summary_lines(record):
    """The text of a fit report (one string per line), lengths and forces in the data's units."""
    p, iv = record.parameters, record.intervals
    show = _display(record)
    lines = [f"source: {record.source['file_name']}", f"sha256: {record.source['sha256']}",
             f"columns: {record.source['columns']}; units in the file: {record.source['units']}",
             *(f"note: {text}" for text in record.source["notes"]),
             f"fit: {'succeeded' if record.success else 'FAILED'} (status {record.status}); "
             f"{record.settings['segment']} segment, {int(p['n_points'])} rows; baseline {record.settings['baseline_model']}; "
             f"{record.settings['weights']} weights; model: " + _MODEL_WORDS[record.settings.get("model", "shell"), bool(record.scene.closed)]]

    def line(name, extra=""):
        value, unit = show(p[name], PARAMETER_UNITS[name])
        lo, hi = (show(v, PARAMETER_UNITS[name])[0] for v in iv[name])
        return f"{name} = {value} {unit}   95% CI [{lo}, {hi}] {unit}{extra}"

    lines += [line(name) for name in record.fitted]
    lines += [line(name, " (linearised)") for name in iv if name not in record.fitted]  # a shape parameter's derived
    rms, R_L = show(p["residual_rms"], "N"), show(p["R_L"], "m")
    lines.append(f"rms residual = {rms[0]} {rms[1]}; R_L = {R_L[0]} {R_L[1]}")
    if record.settings.get("weights_check"):
        lines.append(record.settings["weights_check"])
    for name, what in (("max_depth", "depths up to {} beyond the contact point's first guess"),
                       ("max_force", "forces up to {}")):
        if np.isfinite(p.get(name, np.nan)):
            lines.append("range: " + what.format(" ".join(show(p[name], PARAMETER_UNITS[name]))))
    lines += diagnostics_lines(record.quality, record.fitted, record.correlation, p,
                               lambda v: " ".join(show(v, "N")))
    s = record.scene
    if s.thickness is not None and "beta" not in record.fitted:
        if "mu" not in iv:  # mu of a given thickness (a fitted one's is a line above)
            H = s.thickness * p["R_L"]
            lo, hi = iv["mu_H"]
            lines.append(f"mu = {p['mu_H'] / H / 1e6:.5g} MPa   95% CI [{lo / H / 1e6:.5g}, {hi / H / 1e6:.5g}] "
                         f"(thickness H = {H * 1e6:.4g} um, eps = {s.thickness:.3g})")
        if record.settings.get("model_note"):
            lines.append(f"model: {record.settings['model_note']}")
        if record.settings.get("model", "shell") == "shell" and record.settings.get("model_error_source") != "measured":
            lines.append(model_error_line(s))
        if record.settings.get("stability_verdict"):
            lines.append(record.settings["stability_verdict"])
    lines.append(f"scene: {s.describe(p['R_L'])}")
    lines += [f"warning: {w}" for w in record.warnings] or ["warnings: none"]
    lines.append(f"shellbvp {record.version}; {record.message}")
    return [printable(line) for line in lines]  # text from the file: shown, never obeyed


def fit_report(record, path):
    """A one-page summary of a fit (PNG or PDF by the name's suffix): the figure of
    :func:`plot_fit_record`, the apparent modulus against depth (:func:`plot_apparent_modulus`)
    and the numbers, for a lab notebook."""
    import textwrap

    plt = require_matplotlib()
    fig = plt.figure(figsize=(8.27, 11.69))  # A4 portrait
    ax = fig.add_axes([0.12, 0.62, 0.8, 0.28])
    axr = fig.add_axes([0.12, 0.525, 0.8, 0.09], sharex=ax)
    plot_fit_record(record, (ax, axr))
    plot_apparent_modulus(record, fig.add_axes([0.12, 0.355, 0.8, 0.12]))
    plt.setp(ax.get_xticklabels(), visible=False)
    fig.suptitle("shellbvp fit report", fontsize=13, y=0.95)
    text = "\n".join(textwrap.fill(ln, 110, subsequent_indent="    ") for ln in fit_summary_lines(record))
    fig.text(0.06, 0.30, text, va="top", ha="left", family="monospace", fontsize=6.5)
    try:
        save_figure(fig, path)
    finally:
        plt.close(fig)
    return path
