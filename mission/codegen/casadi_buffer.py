"""Calling a casadi Function from numpy without converting its arguments each call.

``Function.__call__`` turns every numpy argument into a casadi DM, about 60 ns per value: for
the support MPC's ~4,500 parameters that is ~0.2 ms a call, as much as several IPOPT
iterations. casadi's FunctionBuffer instead reads and writes fixed numpy arrays in place.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

SOLVER_EXCEPTION = "SOLVER_RET_EXCEPTION"  # casadi's status for an exception inside the solver


class BufferedFunction:
    """A casadi Function evaluated on arrays it owns: inputs are copied in, outputs copied out.

    Inputs not given to a call keep their last value; ``defaults`` sets their first one
    (otherwise zeros). Only the ``outputs`` named are computed.
    """

    def __init__(
        self,
        function: ca.Function,
        outputs: tuple[str, ...],
        defaults: dict[str, float] | None = None,
    ) -> None:
        self.function = function
        self._buffer, self._evaluate = function.buffer()
        defaults = defaults or {}
        self._inputs: dict[str, np.ndarray] = {}
        for index, name in enumerate(function.name_in()):
            array = np.full(function.nnz_in(index), defaults.get(name, 0.0))
            self._buffer.set_arg(index, memoryview(array))
            self._inputs[name] = array  # the buffer keeps a pointer: the array must live
        self._outputs: dict[str, np.ndarray] = {}
        for name in outputs:
            index = function.index_out(name)
            array = np.zeros(function.nnz_out(index))
            self._buffer.set_res(index, memoryview(array))
            self._outputs[name] = array

    def __call__(self, **inputs: np.ndarray | float) -> dict[str, np.ndarray]:
        """Evaluate with these inputs (by name); the named outputs, as fresh arrays."""
        self._take(inputs)
        self._evaluate()
        return self._results()

    def solve(self, **inputs: np.ndarray | float) -> tuple[dict[str, np.ndarray], bool]:
        """A solver built with ``error_on_fail`` evaluated with these inputs: its named
        outputs (written even where it failed) and whether it succeeded, without the cost of
        :meth:`stats` (a dict of every timer, ~30 us) on a success."""
        self._take(inputs)
        try:
            self._evaluate()
            succeeded = True
        except RuntimeError as error:
            if "error_on_fail" not in str(error):  # not a failed solve: a real error
                raise
            if self.stats().get("unified_return_status") == SOLVER_EXCEPTION:
                raise  # the solver itself broke down, as casadi raised it without the option
            succeeded = False
        return self._results(), succeeded

    def _take(self, inputs: dict[str, np.ndarray | float]) -> None:
        """Copy the given inputs into the arrays the buffer reads."""
        for name, value in inputs.items():
            self._inputs[name][:] = value

    def _results(self) -> dict[str, np.ndarray]:
        """The named outputs of the last evaluation, as fresh arrays."""
        return {name: array.copy() for name, array in self._outputs.items()}

    def stats(self) -> dict:
        """The statistics of the last evaluation (for a solver: return_status, iter_count)."""
        return self._buffer.stats()
