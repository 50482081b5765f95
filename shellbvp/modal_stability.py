r"""Stability of an axisymmetric state against Fourier modes n = 0, 1, 2, ... (issue 44, item 2).

What is solved
--------------
For a state ``x0`` and a perturbation ``eta [u(S) cos(n theta) t + v(S) sin(n theta) e_theta +
w(S) cos(n theta) N]`` the energy is ``Pi0 + eta^2 * 2 pi Int zeta^T A_n(S) zeta dS`` with
``zeta = (u, u', u'', v, v', v'', w, w', w'')`` and ``A_n`` the symmetric 9 x 9 form of
:mod:`symbolic.second_variation` (its coefficients evaluated on the state).  The eigenvalues
returned are those of

.. math:: K q = \lambda M q,\qquad
          \tfrac{d^2\Pi}{d\eta^2} = \lambda \|\delta x\|^2,\quad
          \|\delta x\|^2 = \int\!\!\int |\delta x|^2\, R\Psi\, dS\, d\theta,

i.e. the second derivative of the energy per squared L2 norm of the displacement over the
reference surface (units ``mu H / R_L^2``); for n >= 1 and n = 0 alike
``lambda = 4 Int zeta^T A zeta dS / Int (u^2 + v^2 + w^2) R Psi dS``.  A state is stable
against mode n when its smallest eigenvalue is positive.

Discretisation: Rayleigh-Ritz with cubic Hermite elements (C^1) for all three of u, v, w on a
uniform mesh in S from ``S0`` to the rim.  The form holds ``u''`` and ``v''`` only multiplied
by lower derivatives; C^1 fields make it the exact energy of the discrete fields, so no
integration by parts is needed and the computed eigenvalues are upper bounds of the exact
ones (up to quadrature error, 6 Gauss points per element, and the pole's rounding floor below).  The smallest eigenvalues come from
shift-invert Lanczos (``scipy.sparse.linalg.eigsh``) about a shift that a banded Cholesky
factorisation certifies to lie below the spectrum.

Boundary conditions (states without contact: the inflated/pressurised shell):

* rim (``lambda_theta = 1, z = 0, M_s = 0``): the rim circle is held, so every displacement of
  it vanishes, ``u = v = w = 0``; ``w'`` is free (its natural condition is ``M_s = 0``).  With
  the rim circle fixed, the surface that closes the shell at the rim stays the flat disc, across
  which ``(x, y, 0)/2`` has no flux: the pressure's term is the exact volume, no rim term is left.
  Rigid motions move the rim, so none survives at n = 1 (no tilt to remove).
* pole: the fields of a smooth displacement at the axis, per n (``U cos + V sin`` of
  ``e_x = cos(theta) e_r - sin(theta) e_theta`` at n = 1):

  ====  ==========================================  ===================================
  n     behaviour at S -> 0                          imposed at S0
  ====  ==========================================  ===================================
  0     u, v ~ S, w ~ const + S^2                   u = v = 0, w' = 0
  1     u, v ~ const with u + v -> 0, w ~ S         u + v = 0, w = S0 w'
  >= 2  u, v ~ S^(n-1), w ~ S^n                     u = v = w = 0, w' = 0
  ====  ==========================================  ===================================

  The conditions imposed are those without which the energy diverges (the coefficients carry
  up to ``1/r^3``); higher-order ones (``u' = 0`` for n >= 3, ...) follow from finite energy in
  the limit and are not imposed.  At n = 1, ``w = 0`` at S0 would hold the small circle S0 still
  against the tilt ``w = a S``, at a bending energy of order ``a^2`` whatever S0 (the
  correction of size ``a S0`` over the length S0): ``w = S0 w'`` there lets the tilt through.  The mesh starts at ``S0``: the state's own pole start
  (``inflation.EPS * L``) by default, with the conditions above imposed there; the result's
  change with ``S0`` is measured in the tests.

Accuracy and cost (measured; tests/test_stability.py, benchmarks/stability_pressure.py): the
default mesh has 24 elements per classical wavelength ``2 pi/k_c``, ``k_c = (3/beta)^(1/4)``;
doubling it moves the critical pressures by less than 1e-4 of p_c.  Near the pole the form's
coefficients (up to ``1/r^3``) are evaluated numerically from the generated expressions, and
their cancellation leaves a floor of about 1e-4 of the eigenvalues' scale at S0 = 1.5e-4 (the
rigid motions of a complete sphere come out at that level instead of 0), growing as S0 -> 0
(1e-2 at S0 = 1e-5); regularised pole expressions per n would remove it.  The form's 45 entries
are generated code (``symbolic.second_variation.form_module_source``, numpy with CSE), derived
once per structure into the code cache (``stability_<key>.py``, ~5-10 s) and imported after;
a state of beta 1e-5 (141 elements, n = 0..33) takes about 1 s.

Only states without contact are handled here (topology ``"inflated"``); contact regions (the
normal displacement following the tip, lift-off, walls) and junction terms are not built.
"""

from __future__ import annotations

import functools
import math
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg
import scipy.sparse
import scipy.sparse.linalg

from .geometry import Spheroid

__all__ = ["stability", "Stability", "spectrum", "state_base", "sphere_base", "mesh", "default_modes",
           "default_elements", "END_CONDITIONS", "sphere_stretch"]

#: Gauss points per element.
GAUSS = 6


@dataclass(eq=False)
class Stability:
    """The smallest eigenvalues of the second variation per Fourier mode.

    Attributes
    ----------
    modes : ndarray of int
        The mode numbers n.
    eigenvalues : ndarray, shape (len(modes), count)
        The smallest ``count`` eigenvalues of each mode, ascending (``d^2 Pi/d eta^2`` per squared
        L2 norm of the displacement over the reference surface; module docstring).
    critical_mode : int
        The n of the smallest eigenvalue.
    stable : bool
        Every eigenvalue positive.
    vectors : dict
        Per mode, the eigenvector of its smallest eigenvalue as fields ``S, u, v, w`` at the nodes.
    elements : int
        Elements of the mesh in S.
    S0 : float
        Where the mesh starts (the pole conditions are imposed there).
    wall_time : float
        Seconds (the form's derivation included on first use in a process).

    Examples
    --------
    >>> import shellbvp as sb
    >>> res = sb.stability(sb.inflate(sb.Scene(gamma=1, beta=1e-3)), modes=range(4), elements=20)
    >>> res.stable, res.critical_mode, res.eigenvalues.shape
    (True, 1, (4, 2))
    """

    modes: np.ndarray
    eigenvalues: np.ndarray
    elements: int
    S0: float
    vectors: dict = field(default_factory=dict)
    wall_time: float = math.nan

    @property
    def smallest(self) -> np.ndarray:
        """The smallest eigenvalue of each mode."""
        return self.eigenvalues[:, 0]

    @property
    def critical_mode(self) -> int:
        return int(self.modes[int(np.argmin(self.smallest))])

    @property
    def minimum(self) -> float:
        """The smallest eigenvalue over all modes."""
        return float(np.min(self.smallest))

    @property
    def stable(self) -> bool:
        return bool(self.minimum > 0)

    def __repr__(self):
        return (f"Stability(critical_mode={self.critical_mode}, minimum={self.minimum:.4g}, "
                f"stable={self.stable}, modes={self.modes[0]}..{self.modes[-1]}, elements={self.elements})")


# ------------------------------------------------------------------------------ the form, numeric
@functools.lru_cache(maxsize=16)
def _numeric_form(structure_key):
    """(upper-triangle entry function of the 9 x 9 form, the entries' (i, j), its parameter
    names, the reference shell's parameter names, the reference-shell function) for a structure
    description (a hashable key): the generated module of ``symbolic.second_variation``."""
    import json

    from .model import load_stability_module

    mod = load_stability_module(json.loads(structure_key))
    return mod.form, list(mod.UPPER), list(mod.PARAMS), list(mod.SHELL_PARAMS), mod.reference


def _form_functions(scene):
    import json

    return _numeric_form(json.dumps(scene.structure(), sort_keys=True))


def state_base(state):
    """The base state of ``state`` as a function of S: a dict of ``phi, ls, ks, dls, dks, lt``
    from the inflated state's interpolant (``dls, dks`` its S-derivatives)."""
    return functools.partial(_base_state, state)


def sphere_base(stretch: float):
    """The uniformly stretched sphere ``r = stretch sin S`` of the reference hemisphere (gamma = 1)
    as a base state (no rim layer): the membrane state of a complete sphere under pressure."""
    def base(S):
        one = np.ones_like(S)
        return {"phi": S.copy(), "ls": stretch * one, "ks": one / stretch, "dls": 0 * S, "dks": 0 * S,
                "lt": stretch * one}
    return base


def _base_state(state, S):
    """The base symbols' values at S (dict by name) from an inflated state's interpolant."""
    sysm = state.system
    a, b = sysm.ln_S(sysm.regions[0].start, None), sysm.ln_S(sysm.regions[0].end, None)
    t = (np.log(S) - a) / (b - a)
    y = state.sol(t)
    dy = state.sol.derivative()(t) / (S * (b - a))  # d/dS
    lt, phiS, ls, ks = y[0], y[1], y[2], y[3]
    return {"phi": phiS * S, "ls": ls, "ks": ks, "dls": dy[2], "dks": dy[3], "lt": lt}


def _form_at(scene, base_of, S, n):
    """The 9 x 9 form at the points S (shape (9, 9, len(S))) for mode n."""
    f, upper, params, shell_params, ref = _form_functions(scene)
    values = scene.values()
    R, Psi, dPsi, ks0, kt0 = (np.broadcast_to(np.asarray(v, float), S.shape)
                              for v in ref(S, *[values[p] for p in shell_params]))
    base = base_of(S)
    r = base["lt"] * R
    args = (r, base["phi"], base["ls"], base["ks"], base["dls"], base["dks"], R, Psi, dPsi, ks0, kt0,
            *[values[p] for p in params], n)
    with np.errstate(all="ignore"):
        out = f(*args)
    A = np.empty((9, 9, S.size))
    for (i, j), e in zip(upper, out):
        A[i, j] = A[j, i] = np.broadcast_to(np.asarray(e, float), S.shape)
    return A, R * Psi


# ------------------------------------------------------------------------------ cubic Hermite FEM
def _hermite(xi, h):
    """Values, first and second S-derivatives of the four cubic Hermite shape functions on an
    element of length h at reference points xi in [0, 1] (dofs: f(a), f'(a), f(b), f'(b))."""
    H = np.array([1 - 3 * xi**2 + 2 * xi**3, h * (xi - 2 * xi**2 + xi**3), 3 * xi**2 - 2 * xi**3,
                  h * (-xi**2 + xi**3)])
    dH = np.array([-6 * xi + 6 * xi**2, h * (1 - 4 * xi + 3 * xi**2), 6 * xi - 6 * xi**2,
                   h * (-2 * xi + 3 * xi**2)]) / h
    ddH = np.array([-6 + 12 * xi, h * (-4 + 6 * xi), 6 - 12 * xi, h * (-2 + 6 * xi)]) / h**2
    return H, dH, ddH


def _assemble(scene, base_of, n, nodes):
    """Stiffness K (4 x the form) and Gram M of (u, v, w) on the Hermite mesh (sparse CSR).

    Global dofs: per node ``(u, u', v, v', w, w')``, node-major; derivative dofs times the
    largest element length (so all dofs have the size of the fields)."""
    m = nodes.size
    ndof = 6 * m
    xg, wg = np.polynomial.legendre.leggauss(GAUSS)
    xg, wg = (xg + 1) / 2, wg / 2
    h = np.diff(nodes)
    S = (nodes[:-1, None] + h[:, None] * xg[None, :]).ravel()
    A, area = _form_at(scene, base_of, S, n)
    A = A.reshape(9, 9, m - 1, GAUSS)
    area = area.reshape(m - 1, GAUSS)
    hs = h.max()  # scale of the derivative dofs
    B = np.stack([_element_basis(xg, he, hs) for he in h])  # (elements, 9, 12, GAUSS)
    weights = wg[None, :] * h[:, None]
    Ke = 4 * np.einsum("eiag,ijeg,ejbg,eg->eab", B, A, B, weights, optimize=True)
    G = B[:, [0, 3, 6]]
    Me = np.einsum("eiag,eibg,eg->eab", G, G, weights * area, optimize=True)
    idx = 6 * np.arange(m - 1)[:, None] + np.arange(12)[None, :]
    rows = np.broadcast_to(idx[:, :, None], Ke.shape).ravel()
    cols = np.broadcast_to(idx[:, None, :], Ke.shape).ravel()
    K = scipy.sparse.csr_matrix((Ke.ravel(), (rows, cols)), shape=(ndof, ndof))
    M = scipy.sparse.csr_matrix((Me.ravel(), (rows, cols)), shape=(ndof, ndof))
    return K, M


def _banded(A, bandwidth):
    """The upper band of a symmetric sparse matrix in LAPACK's banded storage."""
    coo = scipy.sparse.triu(A).tocoo()
    ab = np.zeros((bandwidth + 1, A.shape[0]))
    ab[bandwidth + coo.row - coo.col, coo.col] = coo.data
    return ab


def _smallest(K, M, count):
    """The ``count`` smallest eigenvalues (and vectors) of K q = lambda M q, K symmetric, M
    positive definite, both banded sparse: shift-invert Lanczos (``eigsh``) about a shift below
    the spectrum, which a banded Cholesky factorisation of ``K - sigma M`` certifies (it
    exists only when ``K - sigma M`` is positive definite)."""
    coo = K.tocoo()
    bandwidth = int(np.max(np.abs(coo.row - coo.col)))
    Kb, Mb = _banded(K, bandwidth), _banded(M, bandwidth)

    def factor(sigma):
        try:
            return scipy.linalg.cholesky_banded(Kb - sigma * Mb)
        except np.linalg.LinAlgError:
            return None

    # bracket the smallest eigenvalue between a shift that factorises (below it) and one that
    # does not, then bisect: Lanczos about a shift just below the spectrum converges fast
    lo, hi, step = 0.0, None, 1.0
    if factor(lo) is None:
        hi = lo
        while factor(lo) is None:
            lo, step = lo - step, 4 * step
            if step > 1e30:
                raise RuntimeError("no shift below the spectrum found")
    else:
        hi = step
        while factor(hi) is not None:
            lo, hi, step = hi, hi + 4 * step, 4 * step
    for _ in range(60):
        if hi - lo <= 1e-3 * max(1.0, abs(lo)):
            break
        mid = (lo + hi) / 2
        if factor(mid) is None:
            hi = mid
        else:
            lo = mid
    sigma = lo - 1e-3 * max(1.0, abs(lo))
    chol = factor(sigma)
    op = scipy.sparse.linalg.LinearOperator(K.shape, matvec=lambda x: scipy.linalg.cho_solve_banded(
        (chol, False), x), dtype=float)
    lam, X = scipy.sparse.linalg.eigsh(K, k=count, M=M, sigma=sigma, which="LM", OPinv=op, tol=1e-12)
    order = np.argsort(lam)
    return lam[order], X[:, order]


@functools.lru_cache(maxsize=64)
def _element_basis_cached(xg_key, h, hs):
    xg = np.array(xg_key)
    H, dH, ddH = _hermite(xg, h)
    # derivative dofs d = f' * hs: the shape function of d is (shape of f') / hs
    col = np.array([1.0, 1.0 / hs, 1.0, 1.0 / hs])
    H, dH, ddH = H * col[:, None], dH * col[:, None], ddH * col[:, None]
    B = np.zeros((9, 12, xg.size))
    # local dof order: node a (u, u', v, v', w, w'), node b (same); field f in {0: u, 1: v, 2: w}
    for f in range(3):
        cols = [2 * f, 2 * f + 1, 6 + 2 * f, 6 + 2 * f + 1]
        for k, c in enumerate(cols):
            B[3 * f, c] = H[k]
            B[3 * f + 1, c] = dH[k]
            B[3 * f + 2, c] = ddH[k]
    return B


def _element_basis(xg, h, hs):
    return _element_basis_cached(tuple(xg), float(h), float(hs))


#: Dofs (of u, u', v, v', w, w') held at the end S = L: the held rim (``w'`` free: M_s = 0), or
#: the equator of a complete sphere for modes symmetric (u = 0, w' = 0; Q and the in-plane
#: shear vanish naturally) or antisymmetric (v = w = 0; w'' = 0 naturally) about it.
END_CONDITIONS = {"pinned": (0, 2, 4), "symmetric": (0, 5), "antisymmetric": (2, 4)}


def _constraints(n, m, end="pinned", S0_over_hs=0.0):
    """The reduced basis T (sparse, ndof x nfree) that imposes the pole (node 0) and end
    (node m-1) conditions: q = T q_free.  ``S0_over_hs``: S0 over the derivative dofs' scale
    (n = 1's ``w = S0 w'`` at S0)."""
    ndof = 6 * m
    fixed = {6 * (m - 1) + k for k in END_CONDITIONS[end]}
    if n == 0:
        fixed |= {0, 2, 5}  # u = v = 0, w' = 0
    elif n == 1:
        fixed |= {2, 4}  # v(S0) = -u(S0), w(S0) = S0 w'(S0): folded into u's and w''s columns
    else:
        fixed |= {0, 2, 4, 5}
    free = np.array([i for i in range(ndof) if i not in fixed])
    rows, cols, vals = list(free), list(range(free.size)), [1.0] * free.size
    if n == 1:
        rows += [2, 4]
        cols += [int(np.flatnonzero(free == 0)[0]), int(np.flatnonzero(free == 5)[0])]
        vals += [-1.0, S0_over_hs]
    return scipy.sparse.csr_matrix((vals, (rows, cols)), shape=(ndof, free.size))


#: Grading at the pole: the first uniform element is split geometrically (ratio POLE_RATIO)
#: down to a few times S0, so that the quadrature resolves the form's 1/r^k near the pole.
POLE_RATIO = 0.25


def mesh(S0: float, L: float, elements: int) -> np.ndarray:
    """Nodes on [S0, L]: ``elements`` uniform elements, the first split towards S0 geometrically."""
    nodes = np.linspace(S0, L, elements + 1)
    h = nodes[1] - nodes[0]
    extra = []
    d = h * POLE_RATIO
    while d > 4 * S0:
        extra.append(S0 + d)
        d *= POLE_RATIO
    return np.concatenate([nodes[:1], np.array(extra[::-1]), nodes[1:]])


def default_elements(scene) -> int:
    """Elements in S: 24 per local buckling wavelength ``2 pi / k_c``, ``k_c = (3/beta)^(1/4)``
    (the wavenumber of the sphere's classical modes, package units), at least 40."""
    kc = (3.0 / scene.beta) ** 0.25
    return max(40, int(math.ceil(24 * scene.shell_length * kc / (2 * math.pi))))


def default_modes(scene) -> np.ndarray:
    """n = 0 .. N with ``N = ceil(1.3 k_c) + 2``: the classical modes of wavenumber k_c reach
    ``n = k_c r`` on the rim circle (r = 1)."""
    kc = (3.0 / scene.beta) ** 0.25
    return np.arange(0, int(math.ceil(1.3 * kc)) + 3)


def stability(state, modes=None, *, elements: int | None = None, S0: float | None = None,
              count: int = 2, vectors: bool = False) -> Stability:
    """The smallest eigenvalues of the second variation of ``state`` per Fourier mode.

    Parameters
    ----------
    state : Solution
        A converged state without contact: :func:`shellbvp.inflate`'s (topology ``"inflated"``).
    modes : iterable of int, optional
        The mode numbers n (default :func:`default_modes`).
    elements : int, optional
        Cubic Hermite elements in S (default :func:`default_elements`).
    S0 : float, optional
        Where the mesh starts (default: the state's pole start); the pole conditions are imposed
        there (module docstring).
    count : int
        Eigenvalues per mode.
    vectors : bool
        Keep the eigenvector of each mode's smallest eigenvalue.

    Returns
    -------
    Stability
        ``.modes``, ``.eigenvalues`` (per mode the ``count`` smallest), ``.critical_mode``,
        ``.stable``.

    Raises
    ------
    NotImplementedError
        For a state with contact (only the inflated, contact-free state is handled).

    Examples
    --------
    The hemisphere under external pressure (below the bowl) buckles, next to its held rim, at
    about 0.76 of the classical pressure ``4 sqrt(3 beta)`` (benchmarks/results/stability_pressure.md):

    >>> import shellbvp as sb
    >>> scene = sb.Scene(gamma=1, beta=1e-4, pressure=0.8 * 4 * (3e-4) ** 0.5)
    >>> res = sb.stability(sb.inflate(scene))
    >>> res.stable, res.critical_mode
    (False, 11)
    """
    t0 = time.perf_counter()
    if not state.success:
        raise ValueError(f"the state did not converge ({state.message}): no stability for it")
    if state.topology != "inflated":
        raise NotImplementedError(f"stability is built for states without contact (topology 'inflated'); "
                                  f"this state's is {state.topology!r}")
    sysm = state.system
    zeta = float(sysm.S_point(sysm.regions[0].start, None))
    S0 = zeta if S0 is None else max(float(S0), zeta)
    out = spectrum(state.scene, state_base(state), S0, float(sysm.L), modes, elements=elements, count=count,
                   vectors=vectors)
    out.wall_time = time.perf_counter() - t0
    return out


def spectrum(scene, base_of, S0, L, modes=None, *, elements=None, count=2, vectors=False, end="pinned"):
    """The eigenvalues of :func:`stability` for a base state given as a function of S
    (:func:`state_base`, :func:`sphere_base`) on [S0, L], with ``end`` conditions at L
    (:data:`END_CONDITIONS`)."""
    t0 = time.perf_counter()
    ne = elements or default_elements(scene)
    nodes = mesh(S0, L, ne)
    modes = default_modes(scene) if modes is None else np.asarray(sorted(set(int(n) for n in modes)))
    out = np.empty((modes.size, count))
    vecs = {}
    for k, n in enumerate(modes):
        K, M = _assemble(scene, base_of, int(n), nodes)
        T = _constraints(int(n), nodes.size, end, nodes[0] / np.diff(nodes).max())
        Kr, Mr = (T.T @ K @ T).tocsr(), (T.T @ M @ T).tocsr()
        Kr = ((Kr + Kr.T) / 2).tocsr()
        lam, X = _smallest(Kr, Mr, count)
        out[k] = lam
        if vectors:
            q = (T @ X[:, 0]).reshape(-1, 6)
            vecs[int(n)] = {"S": nodes, "u": q[:, 0], "v": q[:, 2], "w": q[:, 4]}
    return Stability(modes=modes, eigenvalues=out, elements=ne, S0=S0, vectors=vecs,
                     wall_time=time.perf_counter() - t0)


def sphere_stretch(scene) -> float:
    """The stretch of the complete sphere (the reference hemisphere, gamma = 1, continued
    through its equator) under the scene's pressure in the membrane state with its uniform
    bending moment: ``kappa_s tau_s + kappa_theta tau_theta = -p`` (the pressure below the bowl
    pushes on its convex side) for ``r = stretch sin S`` (from the generated ``free_profile``)."""
    from scipy.optimize import brentq

    if scene.gamma != 1 or not isinstance(scene.shell, Spheroid):
        raise ValueError("the sphere's membrane state is that of the hemisphere, gamma = 1")
    mod = scene.model()
    par = scene.parameters(mod)
    S = np.array([0.7])

    def residual(stretch):
        y = np.array([[stretch], [1.0], [stretch], [1.0 / stretch], [0.0], [-stretch * math.cos(0.7)]])
        prof = mod.free_profile(S, y, par)
        return float((prof["tau_s"][0] + prof["tau_theta"][0]) / stretch + scene.pressure)

    return brentq(residual, 0.5, 2.0, xtol=1e-14)
