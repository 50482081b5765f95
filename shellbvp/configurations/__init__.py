"""The contact configurations: one module each, registered in one place.

A :class:`Configuration` is what a state's ``topology`` names: its chain of regions
(built from the blocks of :mod:`shellbvp.chain`), the contact models and controls it exists
for, its family (what kind of search finds it) and how its system is built.  Every other
module asks the registry (:func:`configuration`, :func:`names`, :func:`of`,
:func:`switch_between`; :mod:`shellbvp.configurations.registry`) instead of listing names.

Each other module of this package declares one configuration:

* ``ORDER``, an integer: where it stands among the configurations;
* its chain declaration, ``<name>_chain(eps, L[, model])`` (a :class:`shellbvp.chain.Chain`);
* ``CONFIGURATIONS``, a tuple holding its :class:`Configuration` (two where two configurations
  are one declaration);
* ``SWITCHES``, a tuple of the switches (:class:`Switch`) a curve locates between it and
  configurations registered before it: a switch lives in the module of the later of its two.

On import the package finds its modules (:func:`discover`) and registers them in the order
of their ``ORDER`` numbers (:func:`install`); a module without one, or two with the same,
stop the import with a ValueError.  That order is :func:`names`' and therefore the order in
which a state's candidates are tried and listed in files and messages, so it is written in
the modules, not left to their file names.  The numbers go in tens, so that a configuration
can stand between two others.

Adding a configuration is one new module here and its tests: copy the module of a
configuration of its family (``line.py`` for a lifted pole, ``cap_line_cylinder.py`` for the
cylinder), give it a new name, ``ORDER`` and chain, set its traits (``askable``,
``inner_edge``, ``line_contact``, ``pole_branch_end``) and declare its switches; its family's
searches (``shellbvp.state.AGAIN``, ``shellbvp.switches.MEASURED``) serve it.  The lifted-pole
search (``shellbvp.liftoff``) tries every askable configuration of its family through
:func:`names` and tells them apart by their traits, so a lifted configuration needs no other
change (``tests/test_configurations.py`` adds a copy of ``line.py`` in a test and solves it).
A wall configuration also needs its guesses from its neighbours (``shellbvp.cylinder``, a
table keyed by pairs of names), and a split one a search
(``shellbvp.liftoff.second_zone_state`` looks for ``cap+line(tip)`` only).
"""

from __future__ import annotations

import sys

from .registry import (CONFIGURATIONS, FAMILIES, SWITCHES, Configuration, Switch, asked,
                       configuration, discover, family_of, install, is_point_load, is_single_cap, names, of, register,
                       register_switch, switch_between, without_edge_model)
from .point import POINT_S0  # the point-load state's s0, which shellbvp.pointload reads

__all__ = ["Configuration", "CONFIGURATIONS", "CONFIGURATION_NAMES", "FAMILIES", "configuration", "names",
           "register", "family_of", "of", "is_single_cap", "is_point_load", "ASKED",
           "Switch", "SWITCHES", "switch_between", "register_switch", "without_edge_model", "discover", "install",
           "asked", "POINT_S0"]

for _module in discover(sys.modules[__name__]):
    install(_module)

#: Every configuration's name (``Solution.topology``, a curve's per-point ``topology``)
CONFIGURATION_NAMES = names()
#: What ``solve(topology=...)`` accepts (:func:`asked`, as the package registers them)
ASKED = asked()
