"""The first run from Python: Along, adaptive control, seed 0, as `mission run` flies it.

python examples/first_run.py [--out DIR]
"""

import argparse

from mission import run

parser = argparse.ArgumentParser()
parser.add_argument("--out", default="example-output/first-run")
parser.add_argument("--quick", action="store_true", help="cut every run at 40 s (a test)")
args = parser.parse_args()

cut = {"run.timeout_s": 40.0} if args.quick else None
r = run("along", method="ac", seed=0, overrides=cut, out=args.out, force=True)
s = r.summary
print(f"completed: {s.completed} at {s.completion_time_s} s, {s.control_cycles} cycles")
print(f"steps in multipath {s.multipath_steps_total}, work UAV error mean {s.work_error_m.mean} m")
print(f"closest approach {s.closest_approach_m} m, least clearance {s.least_clearance_m} m")
truth = r.truth()
print(truth.groupby("vehicle")[["e", "n", "u"]].agg(["min", "max"]).round(1))
