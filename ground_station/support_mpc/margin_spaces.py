"""The margins' half-spaces of every step as one casadi function, compiled like the NLPs.

:class:`ground_station.support_mpc.margins.Margins` defines them; this computes the same values for
boxes and a fixed number of other UAVs, with the same IEEE operations in the same order
(sums left to right, the slots chosen by a stable selection), so the same to the last bit
but the sign of a zero. In Python they took about 80 us a solve, the largest share of what
the margins add to a plan; compiled, a few.

The function's inputs: ``guess`` (3, U), the steps as columns; ``yhat`` (3,); ``others``
(3, m U), other UAV j's step u in column j U + u. Its outputs: ``spaces``, every step's
normals (slot by slot, x y z) then their offsets, as :meth:`Margins.parameters` gives them;
``inside``, how many steps lie on or inside a box (where the caller computes them in
Python, whose closest-point code covers that case).
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

UNUSED_OFFSET = -1.0  # a slot no half-space fills: n = 0, b = -1
MARGIN_SPACES = "margin_half_spaces"  # the function's name (and its library's part)


@dataclass(frozen=True)
class SpaceRules:
    """What the half-spaces are made of: the margins (widened by the allowances), how far a
    piece may be and still be kept, the boxes, how many other UAVs and slots."""

    separation: float  # 0: no half-space from other UAVs
    clearance: float  # 0: none from the structure and the ground
    reach: float
    low: np.ndarray  # (pieces, 3)
    high: np.ndarray
    others: int
    slots: int


def half_spaces_function(rules: SpaceRules, horizon: int) -> ca.Function:
    """The casadi function of the half-spaces of a horizon of ``horizon`` steps."""
    guess = ca.SX.sym("guess", 3, horizon)
    yhat = ca.SX.sym("yhat", 3)
    others = ca.SX.sym("others", 3, horizon * rules.others)
    normals: list[ca.SX] = []
    offsets: list[ca.SX] = []
    inside = ca.SX(0)
    for u in range(horizon):
        point = [guess[k, u] for k in range(3)]
        spaces = [
            _apart(point, yhat, others[:, j * horizon + u], rules.separation)
            for j in range(rules.others if rules.separation > 0 else 0)
        ]
        if rules.clearance > 0:
            for low, high in zip(rules.low.tolist(), rules.high.tolist(), strict=True):
                space, on_it = _clear_of(point, low, high, rules)
                spaces.append(space)
                inside += on_it
            spaces.append((ca.SX(0), ca.SX(0), ca.SX(1), ca.SX(rules.clearance)))  # the ground
        for nx, ny, nz, b in _nearest_to_binding(point, spaces, rules.slots):
            normals += [nx, ny, nz]
            offsets.append(b)
    spaces_out = ca.vertcat(*normals, *offsets)
    return ca.Function(
        MARGIN_SPACES,
        [guess, yhat, others],
        [spaces_out, inside],
        ["guess", "yhat", "others"],
        ["spaces", "inside"],
    )


def _apart(point, yhat, other, separation: float) -> tuple:
    """The half-space at ``separation`` beyond the other UAV's position facing the guess
    (from yhat where the guess sits on it; straight up where both do)."""
    away = [point[k] - other[k] for k in range(3)]
    length = ca.sqrt(_dot(away, away))
    on = length < 1e-9
    away = [ca.if_else(on, yhat[k] - other[k], away[k]) for k in range(3)]
    length = ca.if_else(on, ca.sqrt(_dot(away, away)), length)
    up = length < 1e-9
    away = [
        ca.if_else(up, 0.0, away[0]),
        ca.if_else(up, 0.0, away[1]),
        ca.if_else(up, 1.0, away[2]),
    ]
    length = ca.if_else(up, 1.0, length)
    normal = [away[k] / length for k in range(3)]
    return (*normal, _dot(normal, [other[k] for k in range(3)]) + separation)


def _clear_of(point, low: list[float], high: list[float], rules: SpaceRules) -> tuple:
    """(the half-space at ``clearance`` beyond the box's point closest to the guess, or the
    unused one where the box is out of reach; 1 where the guess is on or inside the box)."""
    near = [ca.fmin(ca.fmax(point[k], low[k]), high[k]) for k in range(3)]
    out = [point[k] - near[k] for k in range(3)]
    gap = ca.sqrt(_dot(out, out))
    normal = [out[k] / gap for k in range(3)]
    far = gap > rules.reach
    kept = [ca.if_else(far, 0.0, normal[k]) for k in range(3)]
    offset = ca.if_else(far, UNUSED_OFFSET, _dot(normal, near) + rules.clearance)
    return (*kept, offset), gap == 0


def _nearest_to_binding(point, spaces: list[tuple], slots: int) -> list[tuple]:
    """The ``slots`` spaces of least n.g - b, ties in their order (a stable selection: bubble
    passes that swap neighbours only where the later one binds strictly sooner); unused
    slots padded."""
    if len(spaces) <= slots:
        unused = (ca.SX(0), ca.SX(0), ca.SX(0), ca.SX(UNUSED_OFFSET))
        return spaces + [unused] * (slots - len(spaces))
    keyed = [(_dot(space[:3], point) - space[3], *space) for space in spaces]
    for first in range(slots):
        for j in range(len(keyed) - 2, first - 1, -1):
            later_first = keyed[j][0] > keyed[j + 1][0]
            a, b = keyed[j], keyed[j + 1]
            keyed[j] = tuple(ca.if_else(later_first, y, x) for x, y in zip(a, b, strict=True))
            keyed[j + 1] = tuple(ca.if_else(later_first, x, y) for x, y in zip(a, b, strict=True))
    return [entry[1:] for entry in keyed[:slots]]


def _dot(a, b):
    """a.b of two 3-vectors, summed left to right as the Python definition sums them."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
