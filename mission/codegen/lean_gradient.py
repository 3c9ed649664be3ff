"""The C of a casadi solver's functions, with a lean ``nlp_grad`` where the parameters'
multipliers are not asked for.

After every solve casadi's Nlpsol evaluates ``nlp_grad`` (f, g and the Lagrangian's gradients
in x *and in p*) when any of ``calc_f``, ``calc_g``, ``calc_lam_x`` or ``calc_lam_p`` is on;
fatrop's interface turns ``calc_f`` and ``calc_g`` on, always. With ``calc_lam_p`` off the
p-gradient is thrown away (its result pointer is null), but the generated code computes it all
the same. For the support MPC that gradient spans the ~4,500 values of the map's window (each
of the forty gathered corner values seeds a dense vector): 88 us of a 0.36 ms solve, a quarter
of it, whatever the iterations. Without ``calc_lam_x`` (casadi's default) the x-gradient is
thrown away too.

:func:`generate_solver_functions` writes the solver's functions as
``Function.generate_dependencies`` does, but with an ``nlp_grad`` whose unused gradients are
structurally zero. f and g are the same expressions, evaluated the same way
(the same values, bit for bit: a test holds it).
"""

from __future__ import annotations

import casadi as ca

LEAN = "nlp_grad without the unused gradients"  # in a build's recipe: the cache key changes with it


def wants_lean_gradient(options: dict) -> bool:
    """Whether a solver with these options never uses nlp_grad's p-gradient."""
    return options.get("calc_lam_p", True) is False and not options.get("calc_multipliers")


def lean_gradient(nlp: dict[str, ca.MX], with_x: bool) -> ca.Function:
    """``nlp_grad`` as casadi defines it (inputs x, p, lam_f, lam_g; outputs f, g and the
    gradients of lam_f f + lam_g'g), the gradient in p an all-zero sparsity, and the one in x
    too unless ``with_x``."""
    x, p, f, g = nlp["x"], nlp["p"], nlp["f"], nlp["g"]
    lam_f = ca.MX.sym("lam_f")
    lam_g = ca.MX.sym("lam_g", g.sparsity())
    lagrangian = lam_f * f + ca.dot(lam_g, g)
    gradient_x = ca.gradient(lagrangian, x) if with_x else ca.MX(ca.Sparsity(*x.shape))
    return ca.Function(
        "nlp_grad",
        [x, p, lam_f, lam_g],
        [f, g, gradient_x, ca.MX(ca.Sparsity(*p.shape))],
        ["x", "p", "lam_f", "lam_g"],
        ["f", "g", "grad_gamma_x", "grad_gamma_p"],
    )


def generate_solver_functions(
    solver: ca.Function, nlp: dict[str, ca.MX], options: dict, source: str
) -> None:
    """Write the C of ``solver``'s oracle and of every function it evaluates to ``source``
    (working directory), ``nlp_grad`` the lean one (with the x-gradient where ``options``
    ask for ``lam_x``)."""
    lean = lean_gradient(nlp, with_x=bool(options.get("calc_lam_x", False)))
    generator = ca.CodeGenerator(source)
    generator.add(solver.oracle())
    for name in solver.get_function():
        generator.add(lean if name == "nlp_grad" else solver.get_function(name))
    generator.generate()
