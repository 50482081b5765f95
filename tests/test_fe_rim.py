"""The 3D reference's rim, first touch and indenter control (issue 54, item 2).

The rim face held plane and turning about its mid-thickness point (the shell model's simple
support) is a nonlinear constraint solved in its own coordinates: its tangent is checked against
finite differences of its residual; its convergence under refinement, against the pinned point's,
on the paper's seed (slow).  First touch is found where it is: a ring on the seed's inner surface.
"""

import numpy as np
import pytest

import shellbvp as sb

felupe = pytest.importorskip("felupe", reason="the 3D reference needs FElupe ('.[fe]')")

from shellbvp import fe  # noqa: E402
from shellbvp.fe_newton import Newton  # noqa: E402

SEED = sb.Scene.preset("fit", thickness=1 / 6, material=sb.NeoHookean())


def _small_model(scene, eps=1 / 6):
    m = fe._build(scene, eps, through_thickness=2, element_length=1.0, pole_refinement=1, bulk=5000.0,
                  penalty=1e4, gauss_points=3)
    m.contact.bind(m.mesh.points)
    return m


def test_hinged_face_tangent_is_the_derivative_of_its_residual():
    m = _small_model(SEED)
    s = Newton(m, 1e-9)
    s.indenter = 0.02
    rng = np.random.default_rng(0)
    full = np.zeros(int(np.sum(m.field.fieldsizes)))
    full[s.free] = rng.normal(size=s.free.size) * 1e-3
    m.field += full
    m.face.step(m.field[0].values, np.r_[rng.normal(size=m.face.nodes.size) * 1e-3, 0.01], 1.0)
    r, _, Kc, _ = s.residual()
    K, rr, J = s.system(r, m.solid.assemble.matrix(m.field) + Kc)
    K = K.toarray()
    np.testing.assert_allclose(rr, s.system(r, None)[1], rtol=1e-12, atol=1e-14)
    base, h, n = s.save(), 1e-6, rr.size
    face_columns = list(range(n - m.face.nodes.size - 1, n))           # the face's s_k and theta
    for j in face_columns + [0, 7]:
        dq = np.zeros(n)
        dq[j] = 1.0
        sides = []
        for sign in (1, -1):
            s.restore(base)
            s.advance(dq, sign * h)
            sides.append(s.system(s.residual()[0], None)[1])
        fd = (sides[0] - sides[1]) / (2 * h)
        assert np.abs(fd - K[:, j]).max() <= 1e-6 * np.abs(fd).max(), j


def test_face_stays_on_a_line_through_its_mid_point_and_turns():
    c = sb.fe_curve(SEED, 1 / 6, [0.1], at="indenter", element_length=1.0, through_thickness=2)
    assert c.success, c.message
    m = _small_model(SEED)
    assert m.face is not None and m.face.nodes.size == 4                 # 5 face nodes, the mid one fixed
    clamped = _small_model(SEED.replace(rim="clamped"))
    assert clamped.face is None and clamped.fixed.size > m.fixed.size
    point = fe._build(SEED, 1 / 6, through_thickness=2, element_length=1.0, pole_refinement=1, bulk=5000.0,
                      penalty=1e4, gauss_points=3, rim_face="point")
    assert point.face is None
    with pytest.raises(ValueError, match="rim_face must be one of"):
        sb.fe_curve(SEED, 1 / 6, [0.1], rim_face="edge")


def test_first_touch_is_a_ring_where_the_surface_is_more_curved_than_the_tip():
    """The seed's inner surface at the pole (radius of curvature ~0.32) is more curved than its
    tip (rho 1/3): the indenter first touches a ring, above the surface's pole."""
    c = _small_model(SEED).contact
    pole = float(c.X_ref[0, 0, 0])
    assert c.z0 > pole + 1e-4
    d = c.tip.distance(c._at_points(np.zeros(c.ndof_u)), c.z0)[0]
    xq = c._at_points(np.zeros(c.ndof_u))
    assert abs(d.min()) < 1e-10 and xq[np.argmin(d), 1] > 0.05               # touching, off the axis
    hemisphere = _small_model(sb.Scene(gamma=1.0, rho=0.2, material=sb.NeoHookean()), 0.05).contact
    assert hemisphere.z0 == pytest.approx(float(hemisphere.X_ref[0, 0, 0]), abs=1e-14)   # the pole


def test_indenter_control_matches_pole_control():
    scene = sb.Scene.preset("base", material=sb.NeoHookean())
    opts = dict(element_length=1.0, through_thickness=2)
    by_pole = sb.fe_curve(scene, 0.1, [0.05, 0.1], **opts)
    by_tip = sb.fe_curve(scene, 0.1, by_pole.indenter, at="indenter", **opts)
    assert by_pole.success and by_tip.success
    np.testing.assert_allclose(by_tip.delta, by_pole.delta, rtol=1e-5)
    np.testing.assert_allclose(by_tip.force, by_pole.force, rtol=1e-5)
    assert np.all(by_tip.indenter > by_tip.delta) and by_tip.settings["at"] == "indenter"
    with pytest.raises(ValueError, match="at must be"):
        sb.fe_curve(scene, 0.1, [0.05], at="tip")


@pytest.mark.slow  # about 80 s: four meshes of the paper's seed
def test_hinged_face_converges_where_the_pinned_point_does_not():
    """Issue 54: on the paper's seed the pinned mid-thickness point softens as the mesh is refined
    (a ring constraint's compliance); the hinged face converges."""
    depths = [0.05, 0.3]
    meshes = [dict(element_length=0.5, through_thickness=3), dict(element_length=0.25, through_thickness=6)]
    forces = {face: [sb.fe_curve(SEED, 1 / 6, depths, at="indenter", rim_face=face, **mesh).force for mesh in meshes]
              for face in ("plane", "point")}
    plane, point = (np.abs(f[1] / f[0] - 1).max() for f in (forces["plane"], forces["point"]))
    assert plane < 0.005, plane
    assert point > 0.015, point
