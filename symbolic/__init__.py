"""SymPy derivation of the shell equations and their code generation.

Modules: ``materials`` (strain energies), ``geometry`` (shells, tips),
``dag`` (straight-line programs with forward-mode derivatives),
``equations`` (the model: both regions, pole, rim, contact line),
``codegen`` (numpy module printer), ``build`` (structure -> module text).
Nothing is imported here, so that ``shellbvp`` can load cached generated code
without importing SymPy.
"""
