"""Bad files: scenario YAML, what a run asks of the machine, the safety margins' settings and
waypoint files (id, argv builder, texts the one error line must hold)."""

from __future__ import annotations

from mission.link.waypoints import HEADER
from tests.bad_input.builders import (
    FAR_BOX,
    GOOD_ROW,
    HUGE_WORKSPACE,
    MANY_PARTICLES,
    RAISED_LIMIT,
    RUN,
    TWO_ZONES,
    low_deck_scenario,
    mesh_file,
    plan_dir,
    raw_file,
    scenario_file,
    wpl_args,
    wpl_rows,
)


def _fault_case(case: str, fields: str, field: str, problem: str) -> tuple:
    """A scenario whose one fault is ``{fields}`` (at 10 s unless they say), refused naming
    ``faults[0].FIELD`` and the problem."""
    text = f"faults: [{{{'' if 'at_s' in fields else 'at_s: 10, '}{fields}}}]\n"
    return (
        case,
        lambda t: [*RUN, str(scenario_file(t, text))],
        ["bad.yaml", f"faults[0].{field}", problem],
    )


OVERLAP = (
    "faults:\n"
    "  - {at_s: 10, vehicle: support-2, failure: gps off, duration_s: 30}\n"
    "  - {at_s: 20, vehicle: support-2, param: SIM_GPS1_ENABLE, value: 0}\n"
)
OPEN_ENDED_OVERLAP = (  # the later one's end would undo the open-ended "off"
    "faults:\n"
    "  - {at_s: 10, vehicle: support-1, failure: gps off}\n"
    "  - {at_s: 20, vehicle: support-1, failure: gps wrong, duration_s: 5}\n"
)

FLOWN = "vehicle: {dynamics: multicopter, %s}\n"

INSPECTIONS = "task:\n  inspections:\n    - {vehicle: %s, waypoints_m: [%s]}\n"

HYSTERESIS = "roles: {policy: dynamic, release_clear_s: 30, recall_clear_s: 40}\n"
LATE_RECALL = "roles: {policy: dynamic, release_clear_s: 3, recall_clear_s: 2}\n" + INSPECTIONS % (
    "support-1",
    "[0.0, -16.0, 3.0]",
)

GEOMETRY = "world: {zones: [], gnss: {multipath: geometry, %s}}\n"

NEW_PATH = "task: {work_waypoints_m: [[-12.0, -3.0, 7.0], [-12.0, 3.0, 7.0]]}\n"

FILE_CASES = [
    # --- a work path edited in the scenario and not planned again ---------------------------
    (
        "yaml-work-path-not-planned-again",
        lambda t: [*RUN, str(scenario_file(t, NEW_PATH))],
        ["work.waypoints", "task.work_waypoints_m 2", "plan it again"],
    ),
    # --- a support's own inspection waypoints ---------------------------------
    (
        "yaml-inspection-inside-the-structure",
        lambda t: [*RUN, str(scenario_file(t, INSPECTIONS % ("support-1", "[0.0, 0.0, 8.5]")))],
        ["bad.yaml", "task.inspections[0].waypoints_m[0]", "inside the structure"],
    ),
    (
        "yaml-inspection-outside-the-workspace",
        lambda t: [*RUN, str(scenario_file(t, INSPECTIONS % ("support-2", "[0.0, 0.0, 99.0]")))],
        ["bad.yaml", "task.inspections[0].waypoints_m[0]", "outside the workspace"],
    ),
    (
        "yaml-inspection-on-the-ground",
        lambda t: [*RUN, str(scenario_file(t, INSPECTIONS % ("support-2", "[0.0, -16.0, 0.1]")))],
        ["bad.yaml", "task.inspections[0].waypoints_m[0]", "less than control.clearance_m"],
    ),
    (
        "yaml-work-waypoint-on-the-ground",
        lambda t: [
            *RUN,
            str(
                scenario_file(
                    t, "task: {work_waypoints_m: [[-6.0, -3.0, 0.2], [-3.0, -3.0, 7.0]]}\n"
                )
            ),
        ],
        ["bad.yaml", "task.work_waypoints_m[0]", "0.2 m above the ground"],
    ),
    (
        "yaml-inspection-tolerance-tiny",
        lambda t: [*RUN, str(scenario_file(t, "roles: {inspection_tol_m: 1.0e-9}\n"))],
        ["bad.yaml", "roles.inspection_tol_m", "less than control.arrival_tol_m"],
    ),
    (
        "yaml-inspection-of-no-such-support",
        lambda t: [*RUN, str(scenario_file(t, INSPECTIONS % ("support-7", "[0.0, -12.0, 7.0]")))],
        ["bad.yaml", "task.inspections[0].vehicle", "not a support of this scenario"],
    ),
    (
        "yaml-roles-hysteresis-wrong-way-round",
        lambda t: [*RUN, str(scenario_file(t, HYSTERESIS))],
        ["bad.yaml", "roles.release_clear_s", "wrong way round"],
    ),
    (
        "yaml-roles-recall-too-late",
        lambda t: [*RUN, str(scenario_file(t, LATE_RECALL))],
        ["bad.yaml", "roles.recall_clear_s", "support-1", "could not be recalled in time"],
    ),
    (
        "yaml-roles-keep-more-than-the-supports",
        lambda t: [*RUN, str(scenario_file(t, "roles: {keep_in_formation: 4}\n"))],
        ["bad.yaml", "roles.keep_in_formation", "more than the scenario's 3 supports"],
    ),
    # --- the integrity monitor -----------------------------------------------------------
    (
        "yaml-integrity-false-alarm-zero",
        lambda t: [*RUN, str(scenario_file(t, "integrity: {false_alarm: 0}\n"))],
        ["bad.yaml", "integrity.false_alarm", "probability"],
    ),
    (
        "yaml-integrity-missed-detection-nan",
        lambda t: [*RUN, str(scenario_file(t, "integrity: {missed_detection: .nan}\n"))],
        ["bad.yaml", "integrity.missed_detection", "finite"],
    ),
    (
        "yaml-integrity-sustain-longer-than-the-run",
        lambda t: [
            *RUN,
            str(scenario_file(t, "run: {timeout_s: 10}\nintegrity: {sustain_cycles: 30}\n")),
        ],
        ["bad.yaml", "integrity.sustain_cycles", "longer than the run"],
    ),
    (
        "yaml-integrity-unknown-key",
        lambda t: [*RUN, str(scenario_file(t, "integrity: {gates: 3}\n"))],
        ["bad.yaml", "integrity.gates", "unknown key"],
    ),
    (
        "yaml-integrity-motion-sigma-infinite",
        lambda t: [*RUN, str(scenario_file(t, "integrity: {motion_sigma_m: .inf}\n"))],
        ["bad.yaml", "integrity.motion_sigma_m", "finite"],
    ),
    # --- a body, loop or wind the model cannot fly or integrate ---------------
    *[
        (
            f"yaml-flight-{case}",
            lambda t, text=text: [*RUN, str(scenario_file(t, text))],
            ["bad.yaml", field, problem],
        )
        for case, text, field, problem in (
            ("mass", FLOWN % "multicopter: {mass_kg: 1.0e-9}", "multicopter.mass_kg", "mass over"),
            (
                "inertia",
                FLOWN % "multicopter: {inertia_kg_m2: [1.0e-9, 1.0e-9, 1.0e-9]}",
                "multicopter.inertia_kg_m2",
                "cannot integrate",
            ),
            (
                "motor-lag",
                FLOWN % "multicopter: {motor_tau_s: 1.0e-9}",
                "multicopter.motor_tau_s",
                "cannot integrate",
            ),
            (
                "drag",
                FLOWN % "multicopter: {rotor_drag_coefficient: 1.0e+9}",
                "multicopter.mass_kg",
                "mass over the rotors' drag",
            ),
            ("rate-1e6", FLOWN % "multicopter: {rate_hz: 1.0e+6}", "rate_hz", "at most 2000"),
            ("rate-1e300", FLOWN % "multicopter: {rate_hz: 1.0e+300}", "rate_hz", "at most"),
            (
                "rate-gain",
                FLOWN % "autopilot: {rate_gain_per_s: 1.0e+6}",
                "autopilot.rate_gain_per_s",
                "rate loop",
            ),
            (
                "cascade",
                FLOWN % "autopilot: {position_gain_per_s: 1.5}",
                "autopilot.position_gain_per_s",
                "below velocity_gain_per_s",
            ),
            (
                "cascade-too-close",  # the attitude loop too close to the velocity loop
                FLOWN % "autopilot: {velocity_gain_per_s: 5, attitude_gain_per_s: 10}",
                "autopilot.velocity_gain_per_s",
                "by a factor of at least 2.5",
            ),
            ("wind-45", "world: {wind: {speed_m_s: 45}}\n", "wind.speed_m_s", "[0, 40]"),
            ("wind-1e6", "world: {wind: {speed_m_s: 1.0e+6}}\n", "wind.speed_m_s", "[0, 40]"),
            ("turbulence", "world: {wind: {turbulence: 1.0e+6}}\n", "wind.turbulence", "[0, 10]"),
        )
    ],
    # --- safety margins ----------------------------------------------------------------
    (
        "yaml-negative-margin",
        lambda t: [*RUN, str(scenario_file(t, "control: {clearance_m: -1}\n"))],
        ["bad.yaml", "control.clearance_m", "must not be negative"],
    ),
    (
        "yaml-negative-radius",
        lambda t: [*RUN, str(scenario_file(t, "vehicle: {radius_m: -0.1}\n"))],
        ["bad.yaml", "vehicle.radius_m", "must be positive"],
    ),
    (
        "yaml-separation-below-two-bodies",
        lambda t: [*RUN, str(scenario_file(t, "control: {min_separation_m: 0.3}\n"))],
        ["bad.yaml", "control.min_separation_m", "two bodies' radii"],
    ),
    (
        "yaml-clearance-below-a-body",
        lambda t: [*RUN, str(scenario_file(t, "control: {clearance_m: 0.1}\n"))],
        ["bad.yaml", "control.clearance_m", "a body's radius"],
    ),
    (
        "run-plan-breaks-separation",
        lambda t: [*RUN, str(scenario_file(t, "control: {min_separation_m: 3.5}\n"))],
        ["support-1.waypoints", "item", "control.min_separation_m (3.5 m)"],
    ),
    (
        "run-plan-breaks-clearance",
        lambda t: [*RUN, str(scenario_file(t, "control: {clearance_m: 1.5}\n"))],
        ["task.work_waypoints_m[0]", "control.clearance_m (1.5 m)"],
    ),
    # --- scripted faults ---------------------------------------------------------------
    _fault_case(
        "faults-unknown-vehicle", "vehicle: support-7, failure: gps off", "vehicle", "no support-7"
    ),
    _fault_case(
        "faults-unknown-parameter",
        "vehicle: work, param: SIM_X, value: 1",
        "param",
        "no parameter 'SIM_X'",
    ),
    _fault_case(
        "faults-read-only-parameter",
        "vehicle: work, param: SIM_RADIUS, value: 1",
        "param",
        "SIM_RADIUS cannot change during a run",
    ),
    _fault_case(
        "faults-value-out-of-range",
        "vehicle: work, param: SIM_MP_SCALE, value: -1",
        "value",
        "must be in [0, 10]",
    ),
    _fault_case(
        "faults-unknown-failure",
        "vehicle: support-1, failure: camera garbage",
        "failure",
        "a camera failure is one of",
    ),
    _fault_case(
        "faults-past-the-run",
        "at_s: 5000, vehicle: work, failure: gps off",
        "at_s",
        "past the run's end",
    ),
    (
        "faults-overlap",
        lambda t: [*RUN, str(scenario_file(t, OVERLAP))],
        ["bad.yaml", "faults[1]", "overlaps faults[0] on support-2's gps"],
    ),
    (
        "faults-overlap-open-ended",
        lambda t: [*RUN, str(scenario_file(t, OPEN_ENDED_OVERLAP))],
        ["bad.yaml", "faults[1]", "overlaps faults[0] on support-1's gps"],
    ),
    _fault_case(
        "faults-vehicle-with-a-newline",
        'vehicle: "support-1\\n", failure: gps off',
        "vehicle",
        "must be 'work' or 'support-N'",
    ),
    _fault_case(
        "faults-parameter-shorter-than-a-step",
        "vehicle: support-1, param: SIM_MP_SCALE, value: 2, duration_s: 1.0e-20",
        "duration_s",
        "shorter than a vehicle step",
    ),
    _fault_case(
        "faults-failure-shorter-than-a-step",
        "vehicle: support-1, failure: gps off, duration_s: 0.1",
        "duration_s",
        "shorter than a vehicle step",
    ),
    _fault_case(
        "faults-camera-parameter-on-the-work-uav",
        "vehicle: work, param: SIM_CAM_RANGE, value: 5",
        "param",
        "the work UAV carries no camera",
    ),
    # --- scenario YAML -----------------------------------------------------------------
    (
        "yaml-syntax",
        lambda t: [*RUN, str(scenario_file(t, "control: {horizon_steps: [\n"))],
        ["bad.yaml", "invalid YAML"],
    ),
    (
        "yaml-not-a-mapping",
        lambda t: [*RUN, str(raw_file(t, "- 1\n- 2\n"))],
        ["raw.yaml", "mapping"],
    ),
    (
        "unknown-key",
        lambda t: [*RUN, str(scenario_file(t, "control: {horizon: 5}\n"))],
        ["bad.yaml", "horizon"],
    ),
    (
        "wrong-type",
        lambda t: [*RUN, str(scenario_file(t, "control: {horizon_steps: five}\n"))],
        ["bad.yaml", "horizon_steps"],
    ),
    (
        "negative-time",
        lambda t: [*RUN, str(scenario_file(t, "control: {t_pred_s: -1.0}\n"))],
        ["bad.yaml", "t_pred_s", "positive"],
    ),
    (
        "bad-choice",
        lambda t: [*RUN, str(scenario_file(t, "control: {los_penalty: nearest}\n"))],
        ["bad.yaml", "los_penalty"],
    ),
    (
        "zero-sigma-limit",
        lambda t: [*RUN, str(scenario_file(t, "control: {support_max_sigma0_m: 0}\n"))],
        ["bad.yaml", "support_max_sigma0_m"],
    ),
    (
        "nan-number",
        lambda t: [*RUN, str(scenario_file(t, "gnss: {sigma_uere_m: .nan}\n"))],
        ["bad.yaml", "sigma_uere_m"],
    ),
    (
        "bad-epoch",
        lambda t: [*RUN, str(scenario_file(t, "run: {epoch_utc: yesterday}\n"))],
        ["bad.yaml", "epoch_utc"],
    ),
    (
        "extends-missing",
        lambda t: [*RUN, str(raw_file(t, "extends: nowhere.yaml\nname: x\n"))],
        ["nowhere", "extends: no such scenario file"],
    ),
    (
        "extends-itself",
        lambda t: [*RUN, str(raw_file(t, "extends: raw.yaml\nname: x\n"))],
        ["raw.yaml", "extends: too deep (is there a cycle?)"],
    ),
    (
        "mesh-missing",
        lambda t: [*RUN, str(scenario_file(t, "world: {structure: {mesh_file: gone.stl}}\n"))],
        ["gone.stl", "world.structure.mesh_file: no such file"],
    ),
    (
        "mesh-garbage",
        lambda t: [*RUN, str(mesh_file(t, b"\x00\x01not a mesh at all" * 3))],
        ["junk.stl", "holds no triangles"],
    ),
    (
        "mesh-no-normal",
        lambda t: [
            *RUN,
            str(
                mesh_file(t, b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\n", "flat.obj")
            ),
        ],
        ["bad.yaml", "world.structure.mesh_file", "no normal", "face 1"],
    ),
    (
        "yaml-reflection-coefficient",
        lambda t: [*RUN, str(scenario_file(t, GEOMETRY % "amplitude: {water: 1.5}"))],
        ["bad.yaml", "world.gnss.amplitude.water", "[0, 1]"],
    ),
    (
        "yaml-correlator-spacing",
        lambda t: [*RUN, str(scenario_file(t, GEOMETRY % "correlator_spacing_chips: -0.1"))],
        ["bad.yaml", "world.gnss.correlator_spacing_chips", "(0, 1]"],
    ),
    (
        "yaml-geometry-with-zones",
        lambda t: [*RUN, str(scenario_file(t, "world: {gnss: {multipath: geometry}}\n"))],
        ["bad.yaml", "world.gnss.multipath", "zones: []"],
    ),
    (
        "mesh-no-faces",
        lambda t: [*RUN, str(mesh_file(t, b"v 0 0 0\nv 1 0 0\n", "flat.obj"))],
        ["flat.obj", "holds no triangles"],
    ),
    (  # a new structure whose deck sits where the shipped plan flies: plan again
        "mesh-over-the-plan",
        lambda t: [*RUN, str(low_deck_scenario(t))],
        ["work.waypoints", "lies inside the structure", "plan it again (python -m mission plan"],
    ),
    # --- what a run would ask of the machine --------------------------------------------------
    (
        "yaml-voxel-tiny",
        lambda t: [*RUN, str(scenario_file(t, "map: {voxel_size_m: 0.01}\n"))],
        ["map.voxel_size_m", "50 x 40 x 20 m", "limits.max_map_voxels"],
    ),
    (
        "yaml-workspace-huge",
        lambda t: [*RUN, str(scenario_file(t, HUGE_WORKSPACE))],
        ["map.voxel_size_m", "40000 x 40000 x 100 m", "GB"],
    ),
    (
        "yaml-mpc-window",
        lambda t: [
            *RUN,
            str(scenario_file(t, "map: {voxel_size_m: 0.5}\ncontrol: {horizon_steps: 25}\n")),
        ],
        ["map.voxel_size_m", "limits.max_mpc_window_voxels"],
    ),
    (
        "yaml-particles",
        lambda t: [*RUN, str(scenario_file(t, "fusion: {broad_particles: 1000000}\n"))],
        ["fusion.broad_particles", "limits.max_particles"],
    ),
    (
        "yaml-horizon",
        lambda t: [*RUN, str(scenario_file(t, "control: {horizon_steps: 500}\n"))],
        ["control.horizon_steps", "limits.max_horizon_steps"],
    ),
    (
        "yaml-cycles",
        lambda t: [*RUN, str(scenario_file(t, "control: {t_cont_s: 0.0001}\n"))],
        ["control.t_cont_s", "limits.max_control_cycles"],
    ),
    (
        "yaml-memory",
        lambda t: [*RUN, str(scenario_file(t, RAISED_LIMIT))],
        ["map.voxel_size_m", "limits.max_memory_fraction", "this machine"],
    ),
    (
        "yaml-particle-memory",
        lambda t: [*RUN, str(scenario_file(t, MANY_PARTICLES))],
        ["fusion.broad_particles", "limits.max_memory_fraction", "this machine"],
    ),
    (
        "mesh-far-away",
        lambda t: [*RUN, str(mesh_file(t, b"v 0 0 0\nv 1e30 0 0\nv 0 1 0\nf 1 2 3\n", "far.obj"))],
        ["far.obj", "from the anchor"],
    ),
    (
        "yaml-box-far-away",
        lambda t: [*RUN, str(scenario_file(t, FAR_BOX))],
        ["bad.yaml", "world.structure.primitives[0].max_m", "at most"],
    ),
    (
        "yaml-zone-name-newline",
        lambda t: [*RUN, str(scenario_file(t, TWO_ZONES.format(name='"a\\nb"')))],
        ["bad.yaml", "duplicate zone name", "a\\nb"],
    ),
    (
        "yaml-key-newline",
        lambda t: [*RUN, str(scenario_file(t, '"con\\ntrol": {}\n'))],
        ["bad.yaml", "con\\ntrol", "unknown key"],
    ),
    (
        "scenario-file-newline",
        lambda t: [*RUN, str(t / "bad\nname.yaml")],
        ["bad\\nname.yaml", "no such scenario file"],
    ),
    (
        "plan-dir-missing",
        lambda t: [*RUN, str(scenario_file(t, "task: {waypoints_dir: nowhere}\n"))],
        ["nowhere/work.waypoints", "no waypoint file for work"],
    ),
    # --- waypoint files ----------------------------------------------------------------
    ("wpl-header", lambda t: wpl_args(t, "QGC WPL 100\n" + GOOD_ROW), ["work.waypoints", "line 1"]),
    (
        "wpl-empty",
        lambda t: wpl_args(t, ""),
        ["work.waypoints", "first line must be 'QGC WPL 110'"],
    ),
    (
        "wpl-columns",
        lambda t: wpl_args(t, HEADER + "\n" + GOOD_ROW + "2\t0\t3\n"),
        ["work.waypoints", "line 3"],
    ),
    (
        "wpl-not-a-number",
        lambda t: wpl_args(t, HEADER + "\n" + GOOD_ROW.replace("35.15", "north")),
        ["work.waypoints", "line 2"],
    ),
    (
        "wpl-latitude",
        lambda t: wpl_args(t, HEADER + "\n" + GOOD_ROW.replace("35.15", "135.15")),
        ["work.waypoints", "line 2"],
    ),
    (
        "wpl-home-only",
        lambda t: wpl_args(t, wpl_rows()),
        ["work.waypoints", "at least one waypoint"],
    ),
    (
        "wpl-too-many",
        lambda t: wpl_args(t, wpl_rows(*[7.0] * 600)),
        ["work.waypoints", "mission_capacity"],
    ),
    ("wpl-unequal", lambda t: wpl_args(t, wpl_rows(7.0)), ["support-1.waypoints", "pair by index"]),
    (
        "wpl-frame",
        lambda t: wpl_args(t, wpl_rows(7.0, frame=1)),
        ["work.waypoints", "item 1", "frame"],
    ),
    ("wpl-command", lambda t: wpl_args(t, wpl_rows(7.0, command=178)), ["item 1", "command 178"]),
    (
        "wpl-in-deck",
        lambda t: wpl_args(t, wpl_rows(8.5)),
        ["work.waypoints", "inside the structure"],
    ),
    (
        "wpl-too-high",
        lambda t: wpl_args(t, wpl_rows(50.0)),
        ["work.waypoints", "outside the workspace"],
    ),
    (
        "wpl-gcs-in-deck",
        lambda t: ["--waypoints", str(plan_dir(t, "support-3", wpl_rows(8.5)))],
        ["support-3.waypoints", "inside the structure"],
    ),
    (
        "wpl-gcs-file",
        lambda t: ["--waypoints", str(plan_dir(t, "support-2", "garbage\n"))],
        ["support-2.waypoints", "line 1"],
    ),
]
