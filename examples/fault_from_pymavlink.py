"""A fault injected from outside mid-run, as a field engineer's ground station would: the run
in real time (5x) streams to an observer address, where pymavlink listens; at 8 s of
simulated time it switches support-1's GNSS off (``param set SIM_GPS1_ENABLE 0``, sent as
REAL32 as pymavlink and MAVProxy send it) and on again 10 s later. The vehicle says each set,
and the run's summary lists them as events.

    python examples/fault_from_pymavlink.py [--out DIR]
"""

import argparse
import socket
import threading
import time

from pymavlink import mavparm, mavutil

from mission import run

parser = argparse.ArgumentParser()
parser.add_argument("--out", default="example-output/fault")
parser.add_argument("--quick", action="store_true", help="cut every run at 40 s (a test)")
args = parser.parse_args()

with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:  # a free port for the observer
    probe.bind(("127.0.0.1", 0))
    port = probe.getsockname()[1]
observer = mavutil.mavlink_connection(f"udpin:127.0.0.1:{port}", source_system=255)
done = threading.Event()


def inject() -> None:
    """Wait for support-1 (system 2), then set its GNSS off at 8 s and on at 18 s."""
    sets = [(8.0, 0), (18.0, 1)]
    while sets and not done.is_set():
        message = observer.recv_match(type="SYSTEM_TIME", blocking=True, timeout=0.5)
        if message is None or message.get_srcSystem() != 2:
            continue
        seconds = message.time_boot_ms / 1000.0
        if seconds >= sets[0][0]:
            observer.target_system, observer.target_component = 2, 1
            value = sets.pop(0)[1]
            mavparm.MAVParmDict().mavset(observer, "SIM_GPS1_ENABLE", value, retries=3)
            print(f"t = {seconds:.1f} s: SIM_GPS1_ENABLE set to {value}")


injector = threading.Thread(target=inject, daemon=True)
injector.start()
try:
    r = run(
        "along",
        seed=0,
        overrides={"run.timeout_s": 25.0 if args.quick else 30.0},
        out=args.out,
        force=True,
        speedup=5.0,
        observer=f"127.0.0.1:{port}",
    )
finally:
    done.set()
    injector.join(timeout=5)
    observer.close()
time.sleep(0)
for event in r.summary["events"]:
    print(event)
