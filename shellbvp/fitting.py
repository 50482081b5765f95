"""Fit mu*H (and a displacement origin) to a measured force–displacement curve.

The model force scales linearly in mu*H (``F_SI = mu_H R_L F(delta)``), so
one model curve serves the whole fit: it is computed once on a grid of depths
and interpolated (monotone cubic) in delta.  The unknowns are ``mu_H`` and,
optionally, the origin offset ``d0`` of the displacement (real contact points
are uncertain): ``F_i = mu_H R_L F((d_i - d0)/R_L)`` for ``d_i > d0``, 0 before.
Least squares (scipy.optimize.least_squares, analytic Jacobian) with 95 %
confidence intervals from the linearised covariance and Student's t.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize, stats
from scipy.interpolate import PchipInterpolator

from .units import unit_factor

__all__ = ["FitResult", "fit", "read_force_csv", "example_data_path"]


def example_data_path():
    """Path of the synthetic Lepidium-like CSV shipped with the package (README example)."""
    from pathlib import Path

    return Path(__file__).parent / "data" / "lepidium_synthetic.csv"


@dataclass
class FitResult:
    """Result of :func:`fit` (SI units).

    Attributes
    ----------
    mu_H : float
        Shear modulus times thickness, N/m (= um*MPa).
    mu_H_ci95 : (float, float)
    offset, offset_ci95 : float, (float, float)
        Displacement origin d0 in m (0 and (0, 0) when not fitted).
    residual_rms : float
        Root-mean-square force residual, N.
    n : int
        Number of data points used.
    success : bool
    message : str
    curve : Curve
        The model curve (nondimensional) the fit used.
    R_L : float
    """

    mu_H: float
    mu_H_ci95: tuple
    offset: float
    offset_ci95: tuple
    residual_rms: float
    n: int
    success: bool
    message: str
    R_L: float
    curve: object = field(repr=False, default=None)
    _model: object = field(repr=False, default=None)

    def model_force(self, displacement):
        """Fitted model force (N) at displacements (m)."""
        return self._model(np.asarray(displacement, float), self.mu_H, self.offset)

    def to_dict(self):
        return {"mu_H": self.mu_H, "mu_H_ci95": list(self.mu_H_ci95), "offset": self.offset,
                "offset_ci95": list(self.offset_ci95), "residual_rms": self.residual_rms, "n": self.n,
                "success": self.success, "message": self.message, "R_L": self.R_L,
                "units": {"mu_H": "N/m (= um*MPa)", "offset": "m", "residual_rms": "N", "R_L": "m"}}


def _model_curve(scene, delta_max, tol):
    from .continuation import curve

    n = 40
    deltas = delta_max * np.arange(1, n + 1) / n
    c = curve(scene, deltas=deltas, tol=tol, estimate_error=False)
    if len(c) < 3:
        raise RuntimeError(f"the model curve could not be computed ({c.stop_reason})")
    d = np.r_[0.0, c.delta]
    F = np.r_[0.0, c.force]
    return c, PchipInterpolator(d, F, extrapolate=False)


def fit(scene, displacement, force, *, R_L, fit_offset=True, delta_max=None, tol=1e-6, loss="linear"):
    """Least-squares fit of mu*H (and the displacement origin) to measured data.

    Parameters
    ----------
    scene : Scene
        Shape, indenter, material and beta (nondimensional).
    displacement, force : array_like
        Measured indenter displacement (m, > 0 into the shell) and force (N).
    R_L : float
        Rim radius of the sample (m).
    fit_offset : bool
        Also fit the origin of the displacement (contact point).
    delta_max : float, optional
        Largest depth of the model curve (default: 1.2 x the largest measured depth/R_L).
    tol : float
        Collocation tolerance of the model curve.
    loss : str
        scipy.optimize.least_squares loss ('linear', or 'soft_l1' to damp outliers).

    Returns
    -------
    FitResult
    """
    d = np.asarray(displacement, float).ravel()
    f = np.asarray(force, float).ravel()
    if d.shape != f.shape:
        raise ValueError(f"displacement and force must have the same length; got {d.size} and {f.size}")
    keep = np.isfinite(d) & np.isfinite(f)
    d, f = d[keep], f[keep]
    if d.size < 3:
        raise ValueError(f"need at least 3 finite data points; got {d.size}")
    if not (isinstance(R_L, (int, float)) and math.isfinite(R_L) and R_L > 0):
        raise ValueError(f"R_L (rim radius, m) must be a finite number > 0; got {R_L!r}")
    if np.max(d) <= 0:
        raise ValueError("displacement must reach positive values (indentation into the shell)")
    dm = 1.2 * np.max(d) / R_L if delta_max is None else float(delta_max)
    c, F = _model_curve(scene, dm, tol)
    dF = F.derivative()
    top = c.delta[-1]

    def shape(x):  # nondimensional model force, 0 before contact, NaN beyond the curve
        x = np.asarray(x, float)
        out = np.where(x <= 0, 0.0, F(np.clip(x, 0, top)))
        return np.where(x > top, np.nan, out)

    def model(disp, mu_H, d0):
        return mu_H * R_L * shape((disp - d0) / R_L)

    def residual(p):
        mu_H, d0 = (p[0], p[1]) if fit_offset else (p[0], 0.0)
        r = model(d, mu_H, d0) - f
        return np.nan_to_num(r, nan=1e3 * (np.max(np.abs(f)) + 1))

    def jac(p):
        mu_H, d0 = (p[0], p[1]) if fit_offset else (p[0], 0.0)
        x = (d - d0) / R_L
        s = shape(x)
        ds = np.where((x > 0) & (x <= top), dF(np.clip(x, 0, top)), 0.0)
        cols = [R_L * np.nan_to_num(s)]
        if fit_offset:
            cols.append(-mu_H * np.nan_to_num(ds))
        return np.stack(cols, axis=1)

    # mu_H at d0 = 0 from the linear least-squares formula as the start
    s0 = np.nan_to_num(shape(d / R_L))
    mu0 = float(np.dot(s0, f) / max(np.dot(s0, s0), 1e-300) / R_L)
    if not mu0 > 0:
        mu0 = 1.0
    p0 = [mu0, 0.0] if fit_offset else [mu0]
    scale = [mu0, 0.01 * R_L] if fit_offset else [mu0]
    res = optimize.least_squares(residual, p0, jac=jac, x_scale=scale, loss=loss, method="trf")
    J = jac(res.x)
    n, k = d.size, len(res.x)
    rss = float(np.sum(residual(res.x) ** 2))
    dof = max(n - k, 1)
    try:
        cov = np.linalg.inv(J.T @ J) * rss / dof
        half = stats.t.ppf(0.975, dof) * np.sqrt(np.diag(cov))
    except np.linalg.LinAlgError:
        half = np.full(k, np.nan)
    mu_H = float(res.x[0])
    d0 = float(res.x[1]) if fit_offset else 0.0
    off_ci = (d0 - half[1], d0 + half[1]) if fit_offset else (0.0, 0.0)
    off_ci = tuple(float(v) for v in off_ci)
    return FitResult(mu_H=mu_H, mu_H_ci95=(float(mu_H - half[0]), float(mu_H + half[0])), offset=d0,
                     offset_ci95=off_ci,
                     residual_rms=math.sqrt(rss / n), n=n, success=bool(res.success and mu_H > 0),
                     message=res.message, R_L=float(R_L), curve=c, _model=model)


def read_force_csv(path, *, columns=None, units=None):
    """Read displacement and force columns from an instrument's CSV file.

    Accepts a header or none, comma, semicolon or tab delimiters, columns by
    name or 0-based index (default: the first two), units in the header
    (``"Displacement (mm)"``, ``"force [mN]"``) or by ``units=("mm", "mN")``,
    descending or repeated displacements and NaN/empty rows (dropped).
    Returns ``(displacement_m, force_N)`` sorted by displacement.
    Raises ValueError naming the line of a malformed row.
    """
    try:
        text = open(path, newline="", encoding="utf-8-sig").read()
    except OSError as exc:
        raise ValueError(f"{path}: cannot read ({exc.strerror})") from None
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        raise ValueError(f"{path}: no data")
    try:
        dialect = csv.Sniffer().sniff("\n".join(lines[:20]), delimiters=",;\t")
        delim = dialect.delimiter
    except csv.Error:
        delim = "," if "," in lines[0] else (";" if ";" in lines[0] else "\t")
    rows = list(csv.reader(io.StringIO("\n".join(lines)), delimiter=delim))

    def is_number(s):
        try:
            float(s.replace(",", ".") if delim == ";" else s)
            return True
        except ValueError:
            return s.strip().lower() in ("nan", "")

    header = None
    if not all(is_number(c) for c in rows[0]):
        header = [h.strip() for h in rows[0]]
        rows = rows[1:]
    if columns is None:
        cols = (0, 1)
    else:
        cols = []
        for c in columns:
            if isinstance(c, int) or (isinstance(c, str) and c.strip().isdigit()):
                cols.append(int(c))
            else:
                if header is None:
                    raise ValueError(f"{path}: column {c!r} given by name but the file has no header")
                names = [h.split("(")[0].split("[")[0].strip().lower() for h in header]
                key = str(c).strip().lower()
                if key not in names:
                    raise ValueError(f"{path}: no column named {c!r}; columns are {header}")
                cols.append(names.index(key))
        cols = tuple(cols)
    unit_names = list(units) if units is not None else [None, None]
    if units is None and header is not None:
        for i, col in enumerate(cols):
            if col < len(header):
                import re

                m = re.search(r"[\(\[]\s*([^\)\]]+?)\s*[\)\]]", header[col])
                if m:
                    unit_names[i] = m.group(1)
    if unit_names[0] is None or unit_names[1] is None:
        raise ValueError(f"{path}: units unknown; give them in the header, e.g. 'displacement (mm)', "
                         "or with --units mm,mN")
    fd, ff = unit_factor(unit_names[0], "length"), unit_factor(unit_names[1], "force")
    disp, frc = [], []
    first_line = 2 if header is not None else 1
    for n, row in enumerate(rows, start=first_line):
        if all(not c.strip() for c in row):
            continue
        try:
            a, b = (row[c].strip() for c in cols)
        except IndexError:
            raise ValueError(f"{path}: line {n} has {len(row)} columns; need column {max(cols)}") from None
        try:
            va = float(a.replace(",", ".") if delim == ";" else a) if a else float("nan")
            vb = float(b.replace(",", ".") if delim == ";" else b) if b else float("nan")
        except ValueError:
            raise ValueError(f"{path}: line {n}: cannot read {a!r}, {b!r} as numbers") from None
        disp.append(va * fd)
        frc.append(vb * ff)
    d, f = np.array(disp), np.array(frc)
    ok = np.isfinite(d) & np.isfinite(f)
    if ok.sum() < 3:
        raise ValueError(f"{path}: fewer than 3 rows with numbers")
    order = np.argsort(d[ok], kind="stable")
    return d[ok][order], f[ok][order]
