"""The eigenproblem of :mod:`shellbvp.modal_stability`: cubic Hermite elements in S, the pole, rim
and tip constraints per mode, the mesh, and the smallest eigenvalues (:func:`spectrum`)."""

from __future__ import annotations

import functools
import math
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg
import scipy.sparse
import scipy.sparse.linalg

from ..config import OPTIONS
from .form import form_at


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
        Per mode, the eigenvector of its smallest eigenvalue as fields ``S, u, v, w`` and ``dw``
        (``w'``) at the nodes.
    elements : int
        Elements of the mesh in S.
    S0 : float
        Where the mesh starts (the pole conditions are imposed there).
    wall_time : float
        Seconds (the form's derivation included on first use in a process).
    refined : tuple of int
        The modes whose negative eigenvalue was recomputed on a finer mesh (:func:`shellbvp.stability`);
        their rows of ``eigenvalues`` are the finer mesh's.
    held_corners : tuple of float
        The S of the state's cornered contact edges (Weierstrass-Erdmann corners, ``contact_edge``).
        The perturbations keep each at its material point: a negative eigenvalue proves the state
        unstable; a positive one is stability against the perturbations that keep the corners
        there (the corner's own motion through the material is not a degree of freedom here).

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
    held_corners: tuple = ()
    refined: tuple = ()

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


def either_side(results: list) -> "Stability":
    """One :class:`Stability` of the spectra of the same state under other end conditions (a
    closed shell's half: modes symmetric and antisymmetric about its equator): per mode the
    smallest eigenvalues of all, with the eigenvector of the smallest."""
    first = results[0]
    if len(results) == 1:
        return first
    count = first.eigenvalues.shape[1]
    both = np.hstack([r.eigenvalues for r in results])
    owner = np.argmin(np.stack([r.smallest for r in results]), axis=0)
    vectors = {int(n): results[owner[i]].vectors[int(n)] for i, n in enumerate(first.modes)
               if int(n) in results[owner[i]].vectors}
    return Stability(modes=first.modes, eigenvalues=np.sort(both, axis=1)[:, :count], elements=first.elements,
                     S0=first.S0, vectors=vectors, wall_time=sum(r.wall_time for r in results),
                     held_corners=first.held_corners)


def _hermite(xi, h):
    """Values, first and second S-derivatives of the four cubic Hermite shape functions on an
    element of length h at reference points xi in [0, 1] (dofs: f(a), f'(a), f(b), f'(b))."""
    H = np.array([1 - 3 * xi**2 + 2 * xi**3, h * (xi - 2 * xi**2 + xi**3), 3 * xi**2 - 2 * xi**3,
                  h * (-xi**2 + xi**3)])
    dH = np.array([-6 * xi + 6 * xi**2, h * (1 - 4 * xi + 3 * xi**2), 6 * xi - 6 * xi**2,
                   h * (-2 * xi + 3 * xi**2)]) / h
    ddH = np.array([-6 + 12 * xi, h * (-4 + 6 * xi), 6 - 12 * xi, h * (-2 + 6 * xi)]) / h**2
    return H, dH, ddH


def assemble(scene, base_of, n, nodes):
    """Stiffness K (4 x the form) and Gram M of (u, v, w) on the Hermite mesh (sparse CSR).

    Global dofs: per node ``(u, u', v, v', w, w')``, node-major; derivative dofs times the
    largest element length (so all dofs have the size of the fields)."""
    m = nodes.size
    ndof = 6 * m
    xg, wg = np.polynomial.legendre.leggauss(GAUSS)
    xg, wg = (xg + 1) / 2, wg / 2
    elements = np.flatnonzero(np.diff(nodes) > 0)  # a corner's twin nodes bound no element
    h = nodes[elements + 1] - nodes[elements]
    S = (nodes[elements, None] + h[:, None] * xg[None, :]).ravel()
    A, area = form_at(scene, base_of, S, n)
    A = A.reshape(9, 9, elements.size, GAUSS)
    area = area.reshape(elements.size, GAUSS)
    hs = h.max()  # scale of the derivative dofs
    B = np.stack([_element_basis(xg, he, hs) for he in h])  # (elements, 9, 12, GAUSS)
    weights = wg[None, :] * h[:, None]
    Ke = 4 * np.einsum("eiag,ijeg,ejbg,eg->eab", B, A, B, weights, optimize=True)
    G = B[:, [0, 3, 6]]
    Me = np.einsum("eiag,eibg,eg->eab", G, G, weights * area, optimize=True)
    idx = 6 * elements[:, None] + np.arange(12)[None, :]
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


def smallest_pairs(K, M, count):
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


#: Dofs (of u, u', v, v', w, w') held at the end S = L: the held rim, pinned (``w'`` free:
#: M_s = 0) or clamped (``w'`` held too: the slope is), named as ``Scene.rim``; or the equator of
#: a complete sphere for modes symmetric (u = 0, w' = 0; Q and the in-plane shear vanish
#: naturally) or antisymmetric (v = w = 0; w'' = 0 naturally) about it; ``held-symmetric``: a closed
#: shell between plates, symmetric, its spin about the axis (n = 0, v) held at the equator;
#: ``seam``: nothing held, the end tied to the other half's (a closed shell on a substrate,
#: :mod:`shellbvp.modal_stability.closed`).
END_CONDITIONS = {"pinned": (0, 2, 4), "clamped": (0, 2, 4, 5), "symmetric": (0, 5), "antisymmetric": (2, 4),
                  "held-symmetric": (0, 5), "seam": ()}


def constraints(n, m, end="pinned", S0_over_hs=0.0, held=(), pole_held=False, lines=(), stuck=(),
                 stuck_points=(), ties=()):
    """The reduced basis T (sparse, ndof x nfree) that imposes the pole (node 0) and end
    (node m-1) conditions: q = T q_free.  ``S0_over_hs``: S0 over the derivative dofs' scale
    (n = 1's ``w = S0 w'`` at S0).  ``held``: nodes on the tip (``w = w' = 0``: the normal
    displacement vanishes on the contact region, module docstring); ``pole_held``: the pole
    touches the tip at a point (``w = 0`` at S0 for n = 0; the n >= 1 pole conditions hold it
    already or let it slide); ``lines``: the nodes of line contacts (``w = 0`` there);
    ``stuck``: the nodes of regions stuck to the tip (friction="sticking": ``u = v = 0`` on the
    region, so ``u' = v' = 0`` at its nodes, its end nodes included, the fields being C^1);
    ``stuck_points``: lines and a pole held at a point, stuck (``u = v = 0`` at the node only);
    ``ties``: ``(dof, {dof: coefficient})``, a dof given by others (a corner's twin nodes,
    :func:`corner_ties`; n = 1's pole), dropped with the dofs it is given by where it is held."""
    ndof = 6 * m
    fixed = {6 * (m - 1) + k for k in END_CONDITIONS[end]}
    if n == 0 and end == "held-symmetric":  # a closed shell's spin about its axis: no plate resists it
        fixed.add(6 * (m - 1) + 2)
    fixed |= {6 * i + k for i in held for k in (4, 5)}
    fixed |= {6 * i + 4 for i in lines}
    fixed |= {6 * i + k for i in stuck for k in (0, 1, 2, 3)}
    fixed |= {6 * i + k for i in stuck_points for k in (0, 2)}
    tied = dict(ties)
    if n == 1 and (held or pole_held or lines):
        # u = U + O(S^2), v = -U + O(S^2) at the axis: u' = v' = 0.  Where the pole carries a
        # bending prestress (on the tip, or under a point load) the form's u u'' and v v''
        # terms are not small, and without these conditions a layer at S0 lowers the energy
        # without bound as the first element shrinks (measured: tests/test_stability_contact.py)
        fixed |= {1, 3}
    if n == 0:
        fixed |= {0, 2, 5}  # u = v = 0, w' = 0
        if pole_held:
            fixed.add(4)
    elif n == 1:
        tied[2] = {0: -1.0}  # v(S0) = -u(S0)
        if 0 not in held:
            tied[4] = {5: S0_over_hs}  # w(S0) = S0 w'(S0)
        else:
            fixed.add(4)
    else:
        fixed |= {0, 2, 4, 5}
    # a tied dof that is also held: its relation then constrains the dofs it is given by
    for dof in [d for d in tied if d in fixed]:
        fixed |= {k for k, c in tied.pop(dof).items() if c != 0}
    free = np.array([i for i in range(ndof) if i not in fixed and i not in tied])
    column = {int(i): k for k, i in enumerate(free)}
    rows, cols, vals = list(free), list(range(free.size)), [1.0] * free.size
    for dof, by in tied.items():
        for k, c in by.items():
            if k in column:
                rows.append(dof)
                cols.append(column[k])
                vals.append(c)
    return scipy.sparse.csr_matrix((vals, (rows, cols)), shape=(ndof, free.size))


def corner_ties(corner, i, hs):
    """The twin nodes ``i`` (before) and ``i + 1`` (after) of a corner: u, v, w continuous, and the
    normal's rotation about e_theta, ``(w' + phi' u)/lambda_s`` (per Psi), continuous -- so w' jumps
    with lambda_s (module docstring, "Corners"); u' and v' may jump."""
    j = i + 1
    (lm, lp), (fm, fp) = corner.ls, corner.dphi
    return [(6 * j, {6 * i: 1.0}), (6 * j + 2, {6 * i + 2: 1.0}), (6 * j + 4, {6 * i + 4: 1.0}),
            (6 * j + 5, {6 * i + 5: lp / lm, 6 * i: hs * (lp / lm * fm - fp)})]


def corner_energy(corner, i, n, hs):
    """(dofs, 4 Q): the corner's term of the stiffness ``z^T 4 Q z`` over the twin nodes' dofs
    ``z`` (module docstring, "Corners"): each side's moment times the second-order rotation of its
    normal that the displacement makes, and on a contact edge the moments' difference times the
    rotation that keeps the side on the tip."""
    j = i + 1
    (lm, lp), (fm, fp), (Mm, Mp) = corner.ls, corner.dphi, corner.moment
    Psi, r = corner.Psi, corner.r
    # z = (u, u'-, u'+, v, v'-, v'+, w, w'-) as dofs (derivatives times hs)
    dofs = [6 * i, 6 * i + 1, 6 * j + 1, 6 * i + 2, 6 * i + 3, 6 * j + 3, 6 * i + 4, 6 * i + 5]
    omega = np.array([fm, 0, 0, 0, 0, 0, 0, 1 / hs]) / (lm * Psi)  # (w'- + phi'- u)/(lambda- Psi)
    # M+ a+/lambda+ - M- a-/lambda-, a = u' - phi' w; the same with v'
    Ma = np.array([0, -Mm / (hs * lm), Mp / (hs * lp), 0, 0, 0, Mm * fm / lm - Mp * fp / lp, 0])
    Mv = np.array([0, 0, 0, 0, -Mm / (hs * lm), Mp / (hs * lp), 0, 0])
    q = np.array([0, 0, 0, math.sin(corner.phi), 0, 0, -n, 0])  # v sin(phi) - n w
    Q = -(np.outer(omega, Ma) / (2 * Psi) + np.outer(q, Mv) / (2 * Psi * r))
    ks1, kt1 = corner.tip_slope
    c = (Mm - Mp) / (4 * corner.ls[corner.tip_side] * Psi)
    Q[0, 0] += c * ks1
    Q[3, 3] += c * kt1
    return dofs, 4 * (Q + Q.T) / 2


#: Grading at the pole: the first uniform element is split geometrically (ratio POLE_RATIO)
#: down to a few times S0, so that the quadrature resolves the form's 1/r^k near the pole.
POLE_RATIO = 0.25


def mesh(S0: float, L: float, elements: int, edges=()) -> np.ndarray:
    """Nodes on [S0, L]: ``elements`` uniform elements, the first split towards S0 geometrically;
    at each of ``edges`` (contact edges and lines inside (S0, L)) a node and :data:`EDGE_LEVELS`
    nodes on each side at ``h/2, h/4, ...`` from it (the mode's derivatives jump there: without
    the grading the eigenvalues converged only like h)."""
    nodes = np.linspace(S0, L, elements + 1)
    h = nodes[1] - nodes[0]
    steps = h * 0.5 ** np.arange(1, EDGE_LEVELS + 1)
    for edge in edges:
        near = np.concatenate([edge - steps, [edge], edge + steps])
        near = near[(near > S0) & (near < L)]
        # uniform nodes closer than h/2 give way, but not the mesh's start S0 (the pole's conditions are imposed there)
        far = nodes[(np.abs(nodes - edge) >= h / 2) | np.isin(nodes, edges) | (nodes == S0)]
        nodes = np.unique(np.concatenate([far, near]))
    # the first element (uniform, or ending at an edge's nodes near the pole) split towards S0
    extra = []
    d = (nodes[1] - S0) * POLE_RATIO
    while d > 4 * S0:
        extra.append(S0 + d)
        d *= POLE_RATIO
    return np.unique(np.concatenate([nodes, extra]))


def held_nodes(nodes, intervals):
    """The nodes on the tip: within one of the held S-intervals; of a corner's twin nodes at an
    interval's end only the one on the interval's side (the element it bounds lies inside)."""
    held = set()
    for a, b in intervals:
        held |= {int(i) for i in np.flatnonzero((nodes >= a) & (nodes <= b))}
    twin = np.flatnonzero(np.diff(nodes) == 0)
    for i in twin:  # nodes i, i + 1 at one S: keep each only if its element lies inside
        for node, other in ((i, i - 1), (i + 1, i + 2)):
            inside = 0 <= other < nodes.size and any(a <= min(nodes[node], nodes[other]) and
                                                     max(nodes[node], nodes[other]) <= b for a, b in intervals)
            if not inside:
                held.discard(int(node))
    return tuple(sorted(held))


#: Nodes on each side of a contact edge (:func:`mesh`).
EDGE_LEVELS = 8


def local_beta(scene) -> float:
    """The smallest ratio of bending to membrane stiffness along the wall, ``beta t_min^2`` (the
    energy is ``t W + beta t^3 B``, t the thickness over the pole's): ``beta`` for a uniform wall."""
    if scene.thickness_profile is None:
        return scene.beta
    L = scene.shell_length
    t = scene.thickness_profile.relative(np.linspace(0.0, L, 2001), L=L)
    return scene.beta * min(1.0, float(np.min(t))) ** 2


def default_elements(scene) -> int:
    """Elements in S: 24 per local buckling wavelength ``2 pi / k_c``, ``k_c = (3/beta)^(1/4)``
    (the wavenumber of the sphere's classical modes, package units; a profiled wall's at its
    thinnest, :func:`local_beta`), at least 40."""
    kc = (3.0 / local_beta(scene)) ** 0.25
    return max(40, int(math.ceil(24 * scene.shell_length * kc / (2 * math.pi))))


def default_modes(scene) -> np.ndarray:
    """n = 0 .. N with ``N = ceil(1.3 k_c) + 2``: the classical modes of wavenumber k_c reach
    ``n = k_c r`` on the rim circle (r = 1)."""
    kc = (3.0 / local_beta(scene)) ** 0.25
    return np.arange(0, int(math.ceil(1.3 * kc)) + 3)


def checked_modes(scene) -> np.ndarray:
    """The modes :func:`shellbvp.stability` checks unless told: :func:`default_modes`, without
    n = 1 for a closed shell -- between frictionless plates it slides sideways and turns at no
    cost, on a substrate under a curved tip it slips out sideways (negative at every depth) or
    rolls in place (zero): rigid motions of the frictionless model, not buckling
    (:mod:`shellbvp.modal_stability.closed`)."""
    modes = default_modes(scene)
    return modes[modes != 1] if scene.closed else modes


#: Seconds per unknown (summed over the modes) of a state's analysis, measured on the inflated
#: hemisphere: 3.7 s for 250 elements x 59 modes (beta 1e-6), 10 s for 445 x 101 (1e-7).
_SECONDS_PER_DOF = 4e-5


def stability_size(scene, modes=None, elements=None) -> tuple:
    """``(elements, modes, unknowns, seconds)`` of one state's analysis, estimated from the scene
    before anything is built: 6 unknowns per node and mode (u, u', v, v', w, w'); the elements and
    the modes both grow like beta^(-1/4) (:func:`default_elements`, :func:`default_modes`), so the
    cost grows like 1/sqrt(beta).  Negative eigenvalues are recomputed on finer meshes on top."""
    ne = int(elements or default_elements(scene))
    nm = len(default_modes(scene)) if modes is None else len(set(int(n) for n in modes))
    dofs = 6 * (ne + 1) * nm * (2 if scene.two_contacts else 1)  # a closed shell on a substrate: two halves
    return ne, nm, dofs, _SECONDS_PER_DOF * dofs


def check_stability_size(scene, modes=None, elements=None, max_dofs=None) -> None:
    """ValueError, in one line, where one state's analysis exceeds ``max_dofs`` unknowns (default
    ``sb.options``' ``max_stability_dofs``, 300,000: about 15 s)."""
    limit = int(OPTIONS.max_stability_dofs if max_dofs is None else max_dofs)
    ne, nm, dofs, seconds = stability_size(scene, modes, elements)
    if dofs > limit:
        thinnest = " at the thinnest wall" if scene.thickness_profile is not None else ""
        raise ValueError(f"stability: beta = {local_beta(scene):.3g}{thinnest} needs {ne} elements x {nm} modes, {dofs:,} unknowns "
                         f"(about {seconds:,.0f} s per state), over the limit of {limit:,} (max_dofs, "
                         f"--max-stability-dofs): fewer modes (modes=) or a larger limit if the time allows it")


def stiffness(scene, base_of, n, nodes, contact=None):
    """K and M of mode n on ``nodes`` before any constraint: the form (:func:`assemble`) with, for a
    state on the tip, the rings' terms at the edges and lines, the pole's slide (n = 1) and the
    corners' terms (:func:`corner_energy`; a corner's twin nodes are the two nodes at its S)."""
    K, M = assemble(scene, base_of, n, nodes)
    if contact is None:
        return K, M
    hs = np.diff(nodes).max()
    terms = {}

    def add(i, j, value):
        terms[i, j] = terms.get((i, j), 0.0) + value

    for S, (uu, vv, uw, ww) in contact.rings:
        i = 6 * int(np.flatnonzero(nodes == S)[0])
        for (a, b), value in (((i, i), uu), ((i + 2, i + 2), vv), ((i, i + 5), uw / hs), ((i + 5, i), uw / hs),
                              ((i + 5, i + 5), ww / hs**2)):
            add(a, b, value)
    if contact.pole_held and n == 1:  # the pole slides on the tip: -F kappa_apex U^2 / pi (U = u(S0))
        add(0, 0, -contact.pole_force * contact.apex_curvature / np.pi)
    for c in contact.corners:
        dofs, Q = corner_energy(c, int(np.flatnonzero(nodes == c.S)[0]), n, hs)
        for a, da in enumerate(dofs):
            for b, db in enumerate(dofs):
                add(da, db, Q[a, b])
    if terms:
        rows, cols = zip(*terms)
        K = K + scipy.sparse.csr_matrix((list(terms.values()), (rows, cols)), shape=K.shape)
    return K, M


def spectrum(scene, base_of, S0, L, modes=None, *, elements=None, count=2, vectors=False, end="pinned",
             contact=None):
    """The eigenvalues of :func:`stability` for a base state given as a function of S
    (:func:`state_base`, :func:`sphere_base`) on [S0, L], with ``end`` conditions at L
    (:data:`END_CONDITIONS`) and, for a state on the tip, its :class:`Contact`."""
    t0 = time.perf_counter()
    ne = elements or default_elements(scene)
    nodes = mesh(S0, L, ne, () if contact is None else contact.edges)
    if contact is not None:
        nodes = np.sort(np.concatenate([nodes, [c.S for c in contact.corners]]))  # a twin node at each corner
    hs = np.diff(nodes).max()  # the scale of the derivative dofs (assemble)
    held, pole_held, lines, ties, stuck, stuck_points = (), False, (), [], (), ()
    if contact is not None:
        pole_held = contact.pole_held
        held = held_nodes(nodes, contact.held)
        lines = tuple(int(np.flatnonzero(nodes == S)[0]) for S in contact.lines)
        ties = [t for c in contact.corners for t in corner_ties(c, int(np.flatnonzero(nodes == c.S)[0]), hs)]
        if contact.friction == "sticking":
            # u = v = 0 wherever the shell touches the tip: the pressure's, the rings' and the
            # pole's sliding terms then act on held dofs only (a line keeps its rolling term)
            stuck, stuck_points = held, tuple(lines) + ((0,) if pole_held else ())
    modes = default_modes(scene) if modes is None else np.asarray(sorted(set(int(n) for n in modes)))
    out = np.empty((modes.size, count))
    vecs = {}
    for k, n in enumerate(modes):
        K, M = stiffness(scene, base_of, int(n), nodes, contact)
        T = constraints(int(n), nodes.size, end, nodes[0] / hs, held, pole_held, lines, stuck=stuck,
                         stuck_points=stuck_points, ties=ties)
        Kr, Mr = (T.T @ K @ T).tocsr(), (T.T @ M @ T).tocsr()
        Kr = ((Kr + Kr.T) / 2).tocsr()
        lam, X = smallest_pairs(Kr, Mr, count)
        out[k] = lam
        if vectors:
            q = (T @ X[:, 0]).reshape(-1, 6)
            vecs[int(n)] = {"S": nodes, "u": q[:, 0], "v": q[:, 2], "w": q[:, 4],
                            "dw": q[:, 5] / np.diff(nodes).max()}  # w' from its dof (assemble's scale)
    return Stability(modes=modes, eigenvalues=out, elements=ne, S0=S0, vectors=vecs,
                     wall_time=time.perf_counter() - t0,
                     held_corners=() if contact is None else tuple(c.S for c in contact.corners))
