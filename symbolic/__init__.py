"""SymPy derivation of the shell equations and their code generation.

Modules: ``materials`` (strain energies), ``geometry`` (shells, tips),
``dag`` (straight-line programs with forward-mode derivatives),
``equations`` (the model: both regions, pole, rim, contact line),
``codegen`` (numpy module printer), ``build`` (structure -> module text),
``second_variation`` (the energy of a non-axisymmetric mid-surface and its second
variation by Fourier mode, for the stability against such modes).
Nothing is imported here, so that ``shellbvp`` can load cached generated code
without importing SymPy.
"""
