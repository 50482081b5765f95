r"""Formulas from users and files, parsed without running any code.

``sympy.sympify`` is ``eval``: a formula such as ``__import__('os').system(...)``
would run.  Here a formula is parsed by :mod:`ast` (which only builds a tree)
and the tree is walked against a whitelist, building the SymPy expression
node by node:

* numbers (``int`` and finite ``float`` literals), the caller's symbol names,
  ``pi`` and ``E``;
* ``+ - * / **`` and unary ``+``/``-``;
* calls of the functions in :data:`FUNCTIONS` with positional arguments.

Anything else -- attributes, subscripts, strings, lambdas, comprehensions,
keywords, comparisons, unknown names, dunder names, calls to anything off
the list -- raises ``ValueError`` naming the formula and the offending piece.

Files store formulas as the plain text of :func:`formula_text`, which this
parser reads back to the same expression.  Files written before that stored
``sympy.srepr`` text (``Mul(Integer(-2), cos(Symbol('S', positive=True)))``);
``legacy_srepr=True`` additionally accepts exactly the constructors srepr
prints for such formulas (``Add, Mul, Pow, Symbol, Integer, Rational, Float``
with literal arguments), still through the same whitelist.
"""

from __future__ import annotations

import ast
import contextlib
import math

import sympy as sp
from sympy.printing.str import StrPrinter

__all__ = ["FUNCTIONS", "MAX_LENGTH", "parse_formula", "formula_text", "evaluation_errors"]

#: Functions a formula may call: name -> (SymPy function, number of arguments).
FUNCTIONS = {
    "sin": (sp.sin, 1), "cos": (sp.cos, 1), "tan": (sp.tan, 1),
    "asin": (sp.asin, 1), "acos": (sp.acos, 1), "atan": (sp.atan, 1), "atan2": (sp.atan2, 2),
    "sinh": (sp.sinh, 1), "cosh": (sp.cosh, 1), "tanh": (sp.tanh, 1),
    "asinh": (sp.asinh, 1), "acosh": (sp.acosh, 1), "atanh": (sp.atanh, 1),
    "exp": (sp.exp, 1), "log": (sp.log, 1), "sqrt": (sp.sqrt, 1), "Abs": (sp.Abs, 1),
}
CONSTANTS = {"pi": sp.pi, "E": sp.E}
MAX_LENGTH = 2000  # characters; long enough for any energy in the literature, short enough to parse safely
_MAX_POW_DIGITS = 4000  # an exact power of numbers may not exceed this many digits (10**10**10 would hang)

_BINARY = {ast.Add: lambda a, b: a + b, ast.Sub: lambda a, b: a - b, ast.Mult: lambda a, b: a * b,
           ast.Div: lambda a, b: a / b}
_HINTS = {ast.Attribute: " (attribute access)",
          ast.Subscript: " (subscripts)", ast.Lambda: " (lambdas)", ast.Compare: " (comparisons)",
          ast.BoolOp: " (boolean operators)", ast.IfExp: " (conditional expressions)"}
# srepr constructors of old files; Symbol assumptions are keywords with literal True/False.
_LEGACY = {"Add", "Mul", "Pow", "Symbol", "Integer", "Rational", "Float"}


def parse_formula(formula, symbols: dict, *, name: str, legacy_srepr: bool = False) -> sp.Expr:
    """A SymPy expression from a formula, built without evaluating any code.

    Parameters
    ----------
    formula : str, int, float or sympy.Expr
        Text in the grammar of the module docstring.  A SymPy expression is
        accepted too, and is checked by printing and re-parsing it, so it
        obeys the same whitelist (and can be stored as text).
    symbols : dict of str -> sympy.Symbol
        The names the formula may use.
    name : str
        What the formula is (``"W"``, ``"R(S)"``), for error messages.
    legacy_srepr : bool
        Also accept the ``srepr`` constructors of files written before plain
        text (see the module docstring).

    Raises
    ------
    TypeError
        ``formula`` is not text, a number or a SymPy expression.
    ValueError
        The text is not a formula of the grammar; the message names the
        formula and the offending piece.
    """
    if isinstance(formula, sp.Basic):
        # a Symbol is also a Boolean in SymPy: a bare name ("omega") is an expression here
        boolean = isinstance(formula, sp.logic.boolalg.Boolean) and not isinstance(formula, sp.Symbol)
        if not isinstance(formula, sp.Expr) or boolean:
            raise TypeError(f"{name} must be an expression, not {type(formula).__name__} ({formula})")
        for s in formula.free_symbols:
            if s.name not in symbols:
                raise ValueError(f"{name}: unknown name {s.name!r} in {formula}; allowed: {sorted(symbols)}")
        formula = formula_text(formula.xreplace({s: symbols[s.name] for s in formula.free_symbols}))
    elif isinstance(formula, bool) or not isinstance(formula, (str, int, float)):
        raise TypeError(f"{name} must be a formula (text), got {type(formula).__name__}: {formula!r}")
    elif not isinstance(formula, str):
        if not math.isfinite(formula):
            raise ValueError(f"{name} must be finite; got {formula!r}")
        formula = repr(formula)
    if len(formula) > MAX_LENGTH:
        raise ValueError(f"{name}: formula longer than {MAX_LENGTH} characters ({len(formula)})")
    shown = formula if len(formula) <= 80 else formula[:77] + "..."
    try:
        tree = ast.parse(formula.strip(), mode="eval")
    except (SyntaxError, ValueError) as exc:
        raise ValueError(f"{name}: {shown!r} is not a formula ({exc.msg if hasattr(exc, 'msg') else exc})") \
            from None
    except (RecursionError, MemoryError):
        raise ValueError(f"{name}: {shown!r} is nested too deeply") from None
    walker = _Builder(formula.strip(), symbols, name, shown, legacy_srepr)
    try:
        expr = walker.build(tree.body)
    except RecursionError:
        raise ValueError(f"{name}: {shown!r} is nested too deeply") from None
    except ArithmeticError as exc:  # 1.0/0.0 in SymPy's floats
        raise ValueError(f"{name}: {shown!r} is not a finite expression ({type(exc).__name__})") from None
    if not isinstance(expr, sp.Expr) or expr.has(sp.zoo, sp.oo, -sp.oo, sp.nan):
        raise ValueError(f"{name}: {shown!r} is not a finite expression ({expr})")
    if expr.has(sp.I):
        raise ValueError(f"{name}: {shown!r} is not a real expression ({expr})")
    for number in expr.atoms(sp.Float):  # SymPy's floats have no exponent limit; the generated code's have
        v = float(number)
        if not math.isfinite(v) or (v == 0) != bool(number.is_zero):
            raise ValueError(f"{name}: {shown!r} holds a number outside double precision ({number})")
    return expr


class _Builder:
    def __init__(self, text, symbols, name, shown, legacy):
        self.text, self.symbols, self.name, self.shown, self.legacy = text, symbols, name, shown, legacy

    def fail(self, node, why=""):
        piece = ast.get_source_segment(self.text, node) or type(node).__name__
        why = why or _HINTS.get(type(node), "")
        raise ValueError(f"{self.name}: {self.shown!r} is not allowed: {piece!r}{why}; a formula may use numbers, "
                         f"{', '.join(sorted(self.symbols)) or 'no names'}, pi, E, + - * / ** and "
                         f"{', '.join(FUNCTIONS)}")

    def build(self, node):
        if isinstance(node, ast.Constant):
            v = node.value
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                self.fail(node, " (only numbers are literals)")
            if isinstance(v, float) and not math.isfinite(v):
                self.fail(node, " (not a finite number)")
            return sp.Integer(v) if isinstance(v, int) else sp.Float(v)
        if isinstance(node, ast.Name):
            if node.id in self.symbols:
                return self.symbols[node.id]
            if node.id in CONSTANTS:
                return CONSTANTS[node.id]
            self.fail(node, " (dunder names are never allowed)" if node.id.startswith("__") else " (unknown name)")
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
            v = self.build(node.operand)
            return -v if isinstance(node.op, ast.USub) else v
        if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
            return _BINARY[type(node.op)](self.build(node.left), self.build(node.right))
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.BitXor):
            self.fail(node, " (use ** for powers)")
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Pow):
            return self.power(node, self.build(node.left), self.build(node.right))
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
            fname = node.func.id
            if fname in FUNCTIONS:
                func, nargs = FUNCTIONS[fname]
                if node.keywords or len(node.args) != nargs or any(isinstance(a, ast.Starred) for a in node.args):
                    self.fail(node, f" ({fname} takes {nargs} positional argument{'s' * (nargs > 1)})")
                return func(*(self.build(a) for a in node.args))
            if self.legacy and fname in _LEGACY:
                return self.legacy_call(node, fname)
            self.fail(node.func, " (not a permitted function)")
        if isinstance(node, ast.Call):
            self.fail(node.func, _HINTS.get(type(node.func), " (only named functions may be called)"))
        self.fail(node)

    def power(self, node, base, exp):
        if base.is_number and exp.is_number and (base.is_Rational and exp.is_Rational):
            digits = max(len(str(abs(base.p))), len(str(base.q)))
            if digits * abs(float(exp)) > _MAX_POW_DIGITS:
                self.fail(node, " (an exact number too large to compute)")
        return base**exp

    def legacy_call(self, node, fname):
        args = node.args
        if fname == "Symbol":
            if not (len(args) == 1 and isinstance(args[0], ast.Constant) and isinstance(args[0].value, str)):
                self.fail(node)
            if any(not (isinstance(k.value, ast.Constant) and isinstance(k.value.value, bool)) for k in node.keywords):
                self.fail(node, " (Symbol assumptions must be True or False)")
            sym = args[0].value
            if sym not in self.symbols:
                self.fail(node, " (unknown name)")
            return self.symbols[sym]
        if fname == "Float":
            if not (args and isinstance(args[0], ast.Constant) and isinstance(args[0].value, str)
                    and len(args) == 1 and all(k.arg in ("precision", "dps") for k in node.keywords)):
                self.fail(node)
            try:
                v = float(args[0].value)
            except ValueError:
                self.fail(node, " (not a number)")
            if not math.isfinite(v):
                self.fail(node, " (not a finite number)")
            return sp.Float(v)
        if node.keywords:
            self.fail(node)
        vals = [self.build(a) for a in args]
        if fname == "Integer" and len(vals) == 1 and vals[0].is_Integer:
            return vals[0]
        if fname == "Rational" and len(vals) == 2 and all(v.is_Integer for v in vals) and vals[1] != 0:
            return sp.Rational(vals[0], vals[1])
        if fname == "Pow" and len(vals) == 2:
            return self.power(node, *vals)
        if fname in ("Add", "Mul") and vals:
            return sp.Add(*vals) if fname == "Add" else sp.Mul(*vals)
        self.fail(node)


@contextlib.contextmanager
def evaluation_errors(name: str):
    """Turn what SymPy/mpmath raise on a formula's numbers (``exp(exp(exp(exp(1000))))``
    overflows mpmath's integers; deep nesting recurses) into a ValueError naming it."""
    try:
        yield
    except (ArithmeticError, RecursionError) as exc:
        raise ValueError(f"{name}: the formula's numbers cannot be evaluated ({type(exc).__name__}: "
                         f"{' '.join(str(exc).split())[:100]})") from None


class _PlainPrinter(StrPrinter):
    """``str`` printing with floats at full (round-trip) precision."""

    def _print_Float(self, expr):
        return repr(float(expr))


def formula_text(expr: sp.Expr) -> str:
    """Plain text of an expression that :func:`parse_formula` reads back to it."""
    return _PlainPrinter({"order": None}).doprint(expr)
