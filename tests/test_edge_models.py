"""The contact and edge models as registered objects (shellbvp/edge_models.py), and the command
line's choices, each the registry's (issue 57, item 5)."""

import argparse
import pickle

import pytest

import shellbvp as sb
from shellbvp.chain import Edge
from shellbvp.edge_models import EDGE_MODELS, EdgeModel, contact_models, edge_model, register_edge_model
from shellbvp.scene import CONTACT_MODELS


def test_every_model_is_registered_once_with_a_consistent_switch():
    assert tuple(EDGE_MODELS) == ("smooth", "corner", "paper", "pinned")  # the names files hold
    assert contact_models() == CONTACT_MODELS == ("smooth", "paper")
    for name, m in EDGE_MODELS.items():
        assert edge_model(name) is m and edge_model(m) is m and m.name == name and str(m) == name
        assert len(m.conditions) == Edge.rows
        if m.next is not None:  # a curve of the contact model reaches it: it names that model
            assert m.contact and m.next.of == name and not m.next.contact and m.leads_to(m.next)
        assert m.contact == (m.of is None)
    assert [n for n, m in EDGE_MODELS.items() if m.variational] == ["smooth", "corner"]
    assert [n for n, m in EDGE_MODELS.items() if m.jumps] == ["corner"]
    assert [n for n, m in EDGE_MODELS.items() if m.held_at_tip_end] == ["pinned"]
    assert not edge_model("smooth").leads_to(edge_model("pinned"))
    with pytest.raises(ValueError, match=r"contact edge model must be one of \('smooth', 'corner', 'paper', "
                                         r"'pinned'\); got 'rough'"):
        edge_model("rough")
    with pytest.raises(ValueError, match="registered already"):
        register_edge_model(EdgeModel("smooth", "again", ()))


def test_a_chain_holds_the_registered_object_and_reads_as_before():
    """Edge takes a name or the object; a pickled chain (a sweep's worker) holds the same object;
    its description prints the name, as before."""
    e = Edge(0, 1, "corner")
    assert e.model is edge_model("corner") and e == Edge(0, 1, edge_model("corner")) and e != Edge(0, 1)
    assert Edge(0, 1).model is edge_model("smooth")
    assert pickle.loads(pickle.dumps(e)).model is e.model
    assert repr(e) == "Edge(kc=0, kf=1, model='corner')"
    with pytest.raises(ValueError, match="contact edge model must be one of"):
        Edge(0, 1, "rough")


def test_each_model_names_generated_conditions_a_scene_has():
    """Every edge model's residual functions exist in the generated code of a scene whose tip
    ends on a cylinder (where the paper's edge can be held: pinned)."""
    module = sb.Scene.preset("base").model()
    for m in EDGE_MODELS.values():
        for what in ("res", "jac", "jac_par"):
            assert callable(m.function(module, "", what)), (m.name, what)


def test_the_scene_and_its_states_carry_the_models_by_name():
    scene = sb.Scene.preset("base", contact="paper")
    assert scene.contact == "paper" and scene.contact_model is edge_model("paper")
    assert sb.Scene.from_dict(scene.to_dict()).contact_model is scene.contact_model
    with pytest.raises(ValueError, match=r"contact must be one of \('smooth', 'paper'\); got 'corner'"):
        sb.Scene.preset("base", contact="corner")  # an edge a curve switches to, not a scene's model


def _choices():
    """{(subcommand, dest): choices} of every option of the command line that has choices."""
    from shellbvp.cli import build_parser

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return {(name, a.dest): tuple(a.choices) for name, p in sub.choices.items() for a in p._actions
            if a.choices is not None}


def test_the_command_line_choices_are_the_registries():
    """--contact is read from the edge models' registry (without numpy); the other choices the
    parser holds before numpy loads are each compared with the registry the package checks them
    against, so neither can change alone."""
    from shellbvp.configurations import names
    from shellbvp.curve_stability import STABILITY_CHOICES
    from shellbvp.fitting.least_squares import BASELINES, WEIGHTS
    from shellbvp.fitting.solid import FIT_MODELS
    from shellbvp.map_pixels import PIXEL_CHOICES
    from shellbvp.materials import BENDINGS
    from shellbvp.scene import SUPPORTS
    from shellbvp.segments import FIT_SEGMENTS

    registry = {
        "contact": contact_models(), "support": SUPPORTS, "topology": ("auto",) + names("cap"),
        "bending": tuple(f for f, c in BENDINGS.items() if c.cli), "stability": STABILITY_CHOICES,
        "segment": FIT_SEGMENTS, "baseline": ("auto",) + BASELINES, "weights": WEIGHTS, "model": FIT_MODELS,
        "pixels": PIXEL_CHOICES,
        "xi": (0, 1), "invert": ("displacement", "force"),  # no registry: the theory's two, a record's two columns
    }
    found = _choices()
    assert {dest for _, dest in found} == set(registry)  # a new option with choices is added here
    for (command, dest), choices in found.items():
        assert choices == registry[dest], (command, dest)
    with pytest.raises(ValueError, match="topology must be 'auto' or 'cap'"):
        sb.curve(sb.Scene.preset("base"), topology="line")
