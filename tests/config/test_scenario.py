"""Scenario loading: embedded scenarios, overrides, and one clear error per kind of bad input."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import trimesh

from mission.config.errors import ScenarioError
from mission.config.scenario import embedded_scenario_names, load_scenario, read_yaml_mapping
from mission.world.model import World


def test_both_embedded_scenarios_load():
    assert {"along", "wall"} <= set(embedded_scenario_names())
    for name in ("along", "wall"):
        scenario = load_scenario(name)
        assert scenario.name == name
        assert len(scenario.world.zones) == 1
        assert scenario.world.zones[0].offset_m == (1.0, 0.0, 0.0)


def test_packaged_yaml_reads_the_same_as_with_pyyamls_pure_python_safe_loader():
    import yaml

    import mission

    files = sorted((Path(mission.__file__).parent / "scenarios").glob("*.yaml"))
    assert len(files) >= 3
    for path in files:
        assert read_yaml_mapping(path) == yaml.safe_load(path.read_text())


def test_model_defaults_reach_the_settings(along):
    assert along.gnss.sigma_uere_m == 0.10
    assert along.camera.range_m == 30.0
    assert (along.fusion.broad_particles, along.fusion.local_particles) == (300, 100)
    assert (along.map.voxel_size_m, along.map.eta, along.map.neighborhood) == (1.0, 0.3, 1.0)
    assert along.control.horizon_steps == 5
    assert along.control.d_max_support_m == pytest.approx(1.0)
    assert along.run.timeout_s == 900.0
    assert along.task.supports == 3 and along.vehicle.failsafe_s == 2.0


def test_user_scenario_overrides_a_subset(write_scenario):
    path = write_scenario(
        """
        extends: wall
        name: coarse-wall
        map: {voxel_size_m: 2.0}
        control: {w_gnss: 20}
        """
    )
    scenario = load_scenario(str(path))
    assert scenario.name == "coarse-wall"
    assert scenario.map.voxel_size_m == 2.0 and scenario.map.eta == 0.3
    assert scenario.control.w_gnss == 20.0 and scenario.control.w_penalty == 100.0
    assert scenario.world.zones == load_scenario("wall").world.zones


def _box_stl(path: Path) -> Path:
    mesh = trimesh.creation.box(extents=[40.0, 40.0, 1.0])
    mesh.apply_translation([0.0, 0.0, 10.5])
    mesh.export(str(path))
    return path


def test_structure_from_a_mesh_file(write_scenario, tmp_path):
    _box_stl(tmp_path / "roof.stl")
    path = write_scenario("world: {structure: {mesh_file: roof.stl, primitives: []}}\n")
    world = World(load_scenario(str(path)))
    geometry = world.gnss.geometry(np.array([[0.0, 0.0, 5.0], [0.0, 0.0, 15.0]]))
    assert not geometry.has_fix[0], "under the roof"
    assert geometry.has_fix[1]
    assert world.structure.contains(np.array([[0.0, 0.0, 10.5]]))[0]


BAD_INPUTS = [
    ("unknown key", "gnss: {sigma_uere: 0.1}\n", "gnss.sigma_uere", "unknown key"),
    ("wrong type", "gnss: {sigma_uere_m: fast}\n", "gnss.sigma_uere_m", "expected a number"),
    ("bool as number", "camera: {range_m: true}\n", "camera.range_m", "expected a number"),
    ("negative voxel", "map: {voxel_size_m: -1}\n", "map.voxel_size_m", "must be positive"),
    ("eta above one", "map: {eta: 1.5}\n", "map.eta", "must be in [0, 1]"),
    (
        "infinite bound",  # an MPC constraint's bound: fatrop needs it finite
        "control: {support_max_sigma0_m: .inf}\n",
        "control.support_max_sigma0_m",
        "must be finite",
    ),
    ("unknown solver", "control: {mpc_solver: snopt}\n", "control.mpc_solver", "snopt"),
    (
        "integer field",
        "fusion: {broad_particles: 2.5}\n",
        "fusion.broad_particles",
        "expected an integer",
    ),
    (
        "zone outside workspace",
        "world: {zones: [{name: z, min_m: [30, 0, 1], max_m: [31, 1, 2], offset_m: [1, 0, 0]}]}\n",
        "world.zones[0]",
        "outside the workspace",
    ),
    (
        "inverted box",
        "world: {workspace: {min_m: [0, 0, 0], max_m: [-1, 5, 5]}}\n",
        "world.workspace.max_m",
        "must exceed min_m",
    ),
    (
        "short vector",
        "world: {workspace: {min_m: [0, 0]}}\n",
        "world.workspace.min_m",
        "expected 3 values",
    ),
    (
        "missing mesh",
        "world: {structure: {mesh_file: nowhere.stl}}\n",
        "world.structure.mesh_file",
        "no such file",
    ),
    ("bad epoch", "sky: {epoch_utc: yesterday}\n", "sky.epoch_utc", "ISO-8601"),
    (
        "mask out of range",
        "sky: {elevation_mask_deg: 95}\n",
        "sky.elevation_mask_deg",
        "must be in [0, 90)",
    ),
    ("unknown base", "extends: nosuch\n", "extends", "no such scenario"),
    ("bad yaml", "map: {voxel_size_m: [1, 2\n", "line 2, column 1", "but got '<stream end>'"),
    ("not a mapping", "- 1\n- 2\n", "", "must hold a mapping"),
    ("section not mapping", "gnss: 3\n", "gnss", "expected a mapping"),
    ("unknown dynamics", "vehicle: {dynamics: rocket}\n", "vehicle.dynamics", "must be one of"),
    (
        "negative mass",
        "vehicle: {multicopter: {mass_kg: -1.5}}\n",
        "vehicle.multicopter.mass_kg",
        "must be positive",
    ),
    (
        "singular inertia",
        "vehicle: {multicopter: {inertia_kg_m2: [0.04, 0.04, 0]}}\n",
        "vehicle.multicopter.inertia_kg_m2",
        "singular",
    ),
    (
        "integration too slow",
        "vehicle: {multicopter: {rate_hz: 40}}\n",
        "vehicle.multicopter.rate_hz",
        "at least 50",
    ),
    (
        "tilt of 90 degrees",
        "vehicle: {autopilot: {tilt_max_deg: 90}}\n",
        "vehicle.autopilot.tilt_max_deg",
        "[20, 89] degrees",
    ),
    # settings in range alone and then fatal or meaningless in flight (found by a red team)
    (
        "tilt of 1e-9 degrees",
        "vehicle: {autopilot: {tilt_max_deg: 1.0e-9}}\n",
        "vehicle.autopilot.tilt_max_deg",
        "[20, 89] degrees",
    ),
    (
        "velocity bias 1e300",
        "vehicle: {autopilot: {velocity_bias_m_s: 1.0e+300}}\n",
        "vehicle.autopilot.velocity_bias_m_s",
        "at most 1",
    ),
    (
        "thrust 1e300",
        "vehicle: {dynamics: multicopter, multicopter: {rotor_thrust_max_n: 1.0e+300}}\n",
        "vehicle.multicopter.rotor_thrust_max_n",
        "at most 10 times",
    ),
    (
        "torque 1e300",
        "vehicle: {dynamics: multicopter, multicopter: {rotor_torque_max_n_m: 1.0e+300}}\n",
        "vehicle.multicopter.rotor_torque_max_n_m",
        "rotor_thrust_max_n x lever_m",
    ),
    (
        "mass 1e30",
        "vehicle: {multicopter: {mass_kg: 1.0e+30, rotor_thrust_max_n: 1.0e+31}}\n",
        "vehicle.multicopter.mass_kg",
        "at most 100 kg",
    ),
    (
        "tracking noise past SIM_TRACK_NOISE",
        "vehicle: {tracking_noise_m: 11}\n",
        "vehicle.tracking_noise_m",
        "SIM_TRACK_NOISE 11 must be in [0, 10]",
    ),
    (
        "failsafe past FS_GCS_TIMEOUT",
        "vehicle: {failsafe_s: 0.01}\n",
        "vehicle.failsafe_s",
        "FS_GCS_TIMEOUT",
    ),
    (
        "sensor rate rounding to 0 Hz",
        "vehicle: {sensor_hz: 0.4}\n",
        "vehicle.sensor_hz",
        "SIM_GPS1_HZ 0 (rounded)",
    ),
    ("no heartbeat", "vehicle: {heartbeat_hz: 1.0e-300}\n", "vehicle.heartbeat_hz", "at least 0.2"),
    ("status at 1e-9 Hz", "vehicle: {status_hz: 1.0e-9}\n", "vehicle.status_hz", "at least 1 Hz"),
    (
        "lockstep wait of 1e-300 s",
        "vehicle: {lockstep_timeout_wall_s: 1.0e-300}\n",
        "vehicle.lockstep_timeout_wall_s",
        "at least 0.1 s",
    ),
    (
        "sigma_UERE past SIM_GPS_UERE",
        "gnss: {sigma_uere_m: 150}\n",
        "gnss.sigma_uere_m",
        "SIM_GPS_UERE",
    ),
    (
        "camera range past SIM_CAM_RANGE",
        "camera: {range_m: 2000}\n",
        "camera.range_m",
        "SIM_CAM_RANGE",
    ),
    (
        "support speed past WPNAV_SPEED",
        "control: {s_max_support_m_s: 60}\n",
        "control.s_max_support_m_s",
        "WPNAV_SPEED 6000 cm/s must be in [10, 5000]",
    ),
    (
        "work speed of 1e-300",
        "control: {s_max_work_m_s: 1.0e-300}\n",
        "control.s_max_work_m_s",
        "WPNAV_SPEED",
    ),
    ("prediction step 1e6 s", "control: {t_pred_s: 1.0e+6}\n", "control.t_pred_s", "at most 10"),
    ("weight 1e300", "control: {w_gnss: 1.0e+300}\n", "control.w_gnss", "at most 1e+06"),
    (
        "edge gain 1e6",
        "world: {wind: {speed_m_s: 10, edge_gain: 1.0e+6}}\n",
        "world.wind.edge_gain",
        "[1, 2]",
    ),
    (
        "no roughness",
        "world: {wind: {roughness_length_m: 0}}\n",
        "world.wind.roughness_length_m",
        "(0, 0.3]",
    ),
    (
        "a roughness that is not a number",
        "world: {wind: {roughness_length_m: .nan}}\n",
        "world.wind.roughness_length_m",
        "must be finite",
    ),
    (
        "a wake that calms the gusts",
        "world: {wind: {wake_gust_gain: 0.5}}\n",
        "world.wind.wake_gust_gain",
        "raises the turbulence",
    ),
    (
        "an infinite wake gain",
        "world: {wind: {speed_m_s: 5, wake_gust_gain: .inf}}\n",
        "world.wind.wake_gust_gain",
        "must be finite",
    ),
    (
        "zone offset 1e9 m",
        "world: {zones: [{name: z, min_m: [-14, -12, 5], max_m: [-4, -6, 11],"
        " offset_m: [1.0e+9, 0, 0]}]}\n",
        "offset_m",
        "at most 1000 m",
    ),
    (
        "a key written twice",
        "faults: [{at_s: 1, vehicle: support-1, failure: gps off}]\nfaults:\n",
        "column 1",
        "the key 'faults' is written twice",
    ),
    (
        "overlapping rotors",
        "vehicle: {multicopter: {rotor_radius_m: 0.21}}\n",
        "vehicle.multicopter.rotor_radius_m",
        "would overlap",
    ),
    (
        "an infinite ground gain",
        "vehicle: {multicopter: {proximity_clip_radii: 0.25}}\n",
        "vehicle.multicopter.proximity_clip_radii",
        "infinite",
    ),
    (
        "a fault setting a gain the loops could not fly",
        "vehicle: {dynamics: multicopter}\n"
        "faults: [{at_s: 5, vehicle: work, param: MPC_XY_P, value: 1.5}]\n",
        "faults[0].value",
        "below velocity_gain_per_s",
    ),
    (
        "a negative rotor radius",
        "vehicle: {multicopter: {rotor_radius_m: -0.1}}\n",
        "vehicle.multicopter.rotor_radius_m",
        "must be positive",
    ),
    (
        "an unknown ceiling law",
        "vehicle: {multicopter: {ceiling_model: strong}}\n",
        "vehicle.multicopter.ceiling_model",
        "must be one of",
    ),
    (
        "a gain outside its PX4 parameter's range",
        "vehicle: {autopilot: {velocity_gain_per_s: 9}}\n",
        "vehicle.autopilot.velocity_gain_per_s",
        "MPC_XY_VEL_P_ACC 9 must be in [1.2, 5]",
    ),
    (
        "empty structure",
        "world: {structure: {primitives: []}}\n",
        "world.structure.primitives",
        "at least one primitive",
    ),
]


@pytest.mark.parametrize(
    ("case", "text", "field", "problem"), BAD_INPUTS, ids=[c[0] for c in BAD_INPUTS]
)
def test_bad_input_names_file_field_and_problem(write_scenario, case, text, field, problem):
    path = write_scenario(text)
    with pytest.raises(ScenarioError) as caught:
        World(load_scenario(str(path)))
    message = str(caught.value)
    assert str(path) in message
    assert field in message
    assert problem in message
    assert "\n" not in message


def test_malformed_mesh_file_is_reported(write_scenario, tmp_path):
    (tmp_path / "broken.stl").write_bytes(b"solid nothing\nthis is not an stl\n")
    path = write_scenario("world: {structure: {mesh_file: broken.stl}}\n")
    with pytest.raises(ScenarioError, match=r"world\.structure\.mesh_file: .*broken\.stl"):
        World(load_scenario(str(path)))


def test_unknown_epoch_in_table(write_scenario):
    path = write_scenario('sky: {epoch_utc: "2021-10-01T05:00:00Z"}\n')
    with pytest.raises(ScenarioError, match="no satellites at 2021-10-01T05:00:00Z"):
        World(load_scenario(str(path)))


@pytest.mark.slow
def test_cli_prints_one_line_and_exits_2(write_scenario, tmp_path):
    path = write_scenario("map: {voxel_size_m: -1}\n")
    result = subprocess.run(
        [sys.executable, "-m", "mission", "world", str(path), "--plot", str(tmp_path / "w.png")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1
    assert "map.voxel_size_m" in result.stderr and str(path) in result.stderr
    assert result.stdout == ""
    assert list(tmp_path.glob("*.png")) == [] and list(tmp_path.glob(".*part")) == []
