"""Straight-line symbolic programs with forward-mode differentiation.

The model's equations are built as an ordered list of named assignments
(``lt = r/R``, ``T_s = W_ls/lt``, ``det = a11*a22 - a12*a21``, ...), each a small
SymPy expression of the program's inputs and of earlier names.  Jacobians are
derived by the chain rule over that list (forward mode), one small expression
per nonzero partial derivative, instead of differentiating the fully expanded
right-hand side: the expanded Cramer solution of the free region's 2x2 system
is large, its derivative larger, while the chain rule keeps the code linear in
the size of the program.  The same program is then printed as numpy code
(``symbolic.codegen``), keeping only the assignments that the requested
outputs depend on.
"""

from __future__ import annotations

import sympy as sp

__all__ = ["Program"]


class Program:
    """An ordered list of assignments ``name = expr`` over declared inputs.

    Parameters
    ----------
    inputs : sequence of sympy.Symbol
        Independent symbols (states, the coordinate S, run-time parameters).
    """

    def __init__(self, inputs=()):
        self.inputs: list[sp.Symbol] = []
        self.steps: list[tuple[sp.Symbol, sp.Expr]] = []
        self._index: dict[sp.Symbol, int] = {}
        self._expr: dict[sp.Symbol, sp.Expr] = {}
        self._deriv: dict[tuple[sp.Symbol, sp.Symbol], sp.Expr] = {}
        for s in inputs:
            self.add_input(s)

    # -- building ---------------------------------------------------------------
    def add_input(self, sym: sp.Symbol) -> sp.Symbol:
        if sym in self._index or sym in self.inputs:
            raise ValueError(f"symbol {sym} already defined in the program")
        self.inputs.append(sym)
        return sym

    def let(self, name: str, expr, *, always: bool = False) -> sp.Expr:
        """Assign ``name = expr``; returns the symbol (or ``expr`` if it is atomic).

        Numbers and bare symbols are not given a name of their own unless
        ``always``: they are returned as they are, so that trivially zero terms
        vanish from the expressions that use them.  ``always=True`` is for names
        that later assignments refer to by symbol (see :meth:`extend`).
        """
        expr = sp.sympify(expr, strict=True)
        if not always and (expr.is_Number or expr.is_Symbol):
            return expr
        sym = sp.Symbol(name)
        if sym in self._index or sym in self.inputs:
            raise ValueError(f"name {name!r} assigned twice")
        unknown = expr.free_symbols - set(self.inputs) - set(self._index)
        if unknown:
            raise ValueError(f"{name} uses undefined symbols {sorted(map(str, unknown))}")
        self._index[sym] = len(self.steps)
        self._expr[sym] = expr
        self.steps.append((sym, expr))
        return sym

    def extend(self, other: "Program", *, skip_defined: bool = False) -> None:
        """Append the assignments of ``other``; its inputs must be defined here.

        This is how a sub-derivation made over physical variables (``r``,
        ``phi``, ...) is reused over scaled states: the new program defines
        ``r``, ``phi``, ... from its own inputs first, then appends.  Partials
        cached in ``other`` (taken with ``r`` independent) become plain
        assignments here and are differentiated again by the chain rule.
        With ``skip_defined``, assignments to names that are already defined
        here are dropped: e.g. ``lt = r/R`` when ``lt`` is an input and
        ``r = lt R`` was defined from it (the two agree by construction).
        """
        for sym, expr in other.steps:
            if skip_defined and self.is_defined(sym):
                continue
            self.let(sym.name, expr, always=True)

    def renamed(self, suffix: str, subs: dict, keep=()):
        """Copy with every name suffixed, except ``keep``; ``subs`` maps inputs.

        Returns ``(program, mapping)`` where ``mapping`` takes this program's
        symbols to the copy's (apply it to output expressions with ``xreplace``).
        """
        mapping = {}
        for sym in list(self.inputs) + [s for s, _ in self.steps]:
            if sym in subs:
                mapping[sym] = subs[sym]
            elif sym in keep:
                mapping[sym] = sym
            else:
                mapping[sym] = sp.Symbol(sym.name + suffix)
        new = Program([mapping[s] for s in self.inputs])
        for sym, expr in self.steps:
            new.let(mapping[sym].name, expr.xreplace(mapping), always=True)
        return new, mapping

    def is_defined(self, sym) -> bool:
        return sym in self._index or sym in self.inputs

    def expression(self, sym):
        """The assigned expression of ``sym`` (``sym`` itself for inputs)."""
        return self._expr.get(sym, sym)

    # -- differentiation ----------------------------------------------------------
    def _step_symbols_of(self, expr):
        syms = [s for s in expr.free_symbols if s in self._index]
        return sorted(syms, key=self._index.__getitem__)

    def derivative(self, target, wrt: sp.Symbol):
        """d target / d wrt, with every assignment expanded by the chain rule.

        ``target`` is an expression over inputs and assigned names; ``wrt`` is
        an input.  New assignments ``d<name>_d<wrt>`` are added for nontrivial
        partials of assigned names.
        """
        if wrt not in self.inputs:
            raise ValueError(f"can only differentiate with respect to inputs, not {wrt}")
        target = sp.sympify(target, strict=True)
        if target.is_Number:
            return sp.S.Zero
        if target in self._index:
            return self._derivative_of_step(target, wrt)
        result = sp.diff(target, wrt)
        for s in self._step_symbols_of(target):
            ds = self._derivative_of_step(s, wrt)
            if ds != 0:
                result += sp.diff(target, s) * ds
        if result.has(sp.DiracDelta):
            # only from a spline's |S - S_k|^3 terms (a thickness table), where the delta comes
            # multiplied by (S - S_k)^2: zero as a distribution (the spline is C2)
            result = result.replace(lambda e: isinstance(e, sp.DiracDelta), lambda e: sp.S.Zero)
        return result

    def _derivative_of_step(self, sym, wrt):
        key = (sym, wrt)
        if key in self._deriv:
            return self._deriv[key]
        expr = self._expr[sym]
        d = self.derivative(expr, wrt)
        d = self.let(self._fresh(f"d{sym.name}_d{wrt.name}"), d) if d != 0 else sp.S.Zero
        self._deriv[key] = d
        return d

    def _fresh(self, name):
        """``name``, or ``name_2``, ``name_3``, ... if taken (partials of a reused
        sub-derivation may already hold the plain name)."""
        base, k = name, 1
        while self.is_defined(sp.Symbol(name)):
            k += 1
            name = f"{base}_{k}"
        return name

    def jacobian(self, targets, wrt):
        """Matrix [d targets_i / d wrt_j] of expressions over program names."""
        return sp.Matrix([[self.derivative(t, w) for w in wrt] for t in targets])

    # -- evaluation (tests, reference values) ------------------------------------------
    def expand(self, expr):
        """``expr`` with every assigned name replaced by its expression (recursively)."""
        expr = sp.sympify(expr, strict=True)
        steps = self._step_symbols_of(expr)
        while steps:
            expr = expr.xreplace({s: self._expr[s] for s in steps})
            steps = self._step_symbols_of(expr)
        return expr

    def dependencies(self, exprs):
        """Assigned names the given expressions need, in program order."""
        needed: set[sp.Symbol] = set()
        stack = []
        for e in exprs:
            stack.extend(self._step_symbols_of(sp.sympify(e, strict=True)))
        while stack:
            s = stack.pop()
            if s in needed:
                continue
            needed.add(s)
            stack.extend(self._step_symbols_of(self._expr[s]))
        return sorted(needed, key=self._index.__getitem__)
