"""A support's camera looking at the work UAV: the world's camera model at the live
``SIM_CAM_RANGE`` and ``SIM_CAM_NOISE``, then its failures (the work UAV carries none)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.world.camera import CameraModel, Observation
from vehicle_sim.mavlink import telemetry
from vehicle_sim.mavlink.parameters import ParameterTable
from vehicle_sim.sensors.failures import SensorFailures


class Camera:
    """Builds LANDING_TARGET for a vehicle's true position and the work UAV's."""

    def __init__(
        self,
        model: CameraModel,
        rng: np.random.Generator,
        parameters: ParameterTable,
        failures: SensorFailures,
        carried: bool,
    ) -> None:
        self._model = model
        self._rng = rng
        self._parameters = parameters
        self._failures = failures
        self._carried = carried  # False: the work UAV, which sees nothing

    def observe(self, truth: np.ndarray, work_truth: np.ndarray | None) -> Observation:
        """The camera's observation of the work UAV from ``truth`` (not valid without the work
        UAV's truth)."""
        if work_truth is None or not self._carried:
            return Observation(False, None, math.nan)
        value = self._parameters.value
        return self._model.observe(
            truth,
            work_truth,
            self._rng,
            range_m=value("SIM_CAM_RANGE"),
            noise_scale=value("SIM_CAM_NOISE"),
        )

    def reading(self, truth: np.ndarray, work_truth: np.ndarray | None, time_usec: int) -> Any:
        """LANDING_TARGET stamped ``time_usec``; None where a failure publishes nothing."""
        healthy = telemetry.landing_target(self.observe(truth, work_truth), time_usec, 1)
        return self._failures.filter(mavlink2.MAVLINK_MSG_ID_LANDING_TARGET, healthy)
