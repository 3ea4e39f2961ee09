#!/usr/bin/python3
"""The host of cdcr-runtime in the CiA 402 test on vcan (uml_runtime_test.sh),
written with python-can and the protocol's DBC read by canmatrix, so none of
the project's codec is in it. It also listens on the drives' buses, where it
reads the manager's RPDO1 (target position) and the drives' TPDO1 (position
actual value) straight from the CiA 402 objects' bytes.

  uml_host_peer.py move --dbc cdcr.dbc --config drives.json --target "X Y Z"
                   --cables out.csv --pose out.txt [--sequence N] [--deadline S]
      sends the position target, waits for its IK_REPORT (converged), then
      for every drive to sit on its setpoint and the pose to hold still;
      writes the drives' final positions as cable lengths (dataset CSV) and
      the last published pose.
  uml_host_peer.py compare --pose out.txt --replay replay.csv [--tolerance MM]
      the published pose against cdcr-runtime --replay of those lengths.
"""

import argparse
import decimal
import json
import logging
import math
import struct
import sys
import time

RUN = 1  # STATUS STATE
CONVERGED, IN_PROGRESS = 0, 6  # IK_REPORT OUTCOME
TPDO1, RPDO1, SYNC = 0x180, 0x200, 0x080
# CiA 402 drives report 0x6041 bit 10 within 10 counts; the check is tighter:
# the simulated loop settles on the target itself once the ramp has ended.
SETTLED_COUNTS = 1
STILL_SECONDS = 3.0


def fail(message):
    print(f"uml_host_peer: FAILED: {message}", flush=True)
    sys.exit(1)


def say(message):
    print(f"uml_host_peer: {message}", flush=True)


def move(args):
    import can
    logging.getLogger("canmatrix").setLevel(logging.ERROR)  # before its import: it logs the formats it lacks
    import canmatrix.formats
    database = next(iter(canmatrix.formats.loadp(args.dbc).values()))
    frames = {f.arbitration_id.id: f for f in database.frames}
    by_name = {f.name: f for f in database.frames}

    def message(name, signals):
        frame = by_name[name]
        raw = {k: frame.signal_by_name(k).phys2raw(decimal.Decimal(v)) for k, v in signals.items()}
        return can.Message(arbitration_id=frame.arbitration_id.id, data=bytes(frame.encode(raw)), is_extended_id=False)

    with open(args.config) as f:
        config = json.load(f)
    drives = config["drives"]
    host = can.Bus(interface="socketcan", channel="vcan0")
    buses = [can.Bus(interface="socketcan", channel=name) for name in config["buses"]]
    node_cable = {(d["bus"], d["node"]): d["cable"] for d in drives}
    actual = [None] * len(drives)
    target = [None] * len(drives)
    pose = {}
    state = None
    syncs = 0
    last_change = time.monotonic()

    def poll():
        nonlocal state, syncs, last_change
        got = []
        while (msg := host.recv(timeout=0)) is not None:
            frame = frames.get(msg.arbitration_id)
            if frame is None:
                continue
            values = {k: s.phys_value for k, s in frame.decode(bytes(msg.data)).items()}
            if frame.name == "STATUS":
                state = int(values["STATE"])
                # A stale cycle (FAULT for a moment on a slow guest) restarts the wait for stillness.
                if state != RUN:
                    last_change = time.monotonic()
            elif frame.name.startswith("POSE_") and frame.name != "POSE_UNCERTAINTY":
                for k, v in values.items():
                    if k == "SEQUENCE":  # new with every pose
                        continue
                    key = f"{frame.name}_{k}"
                    if pose.get(key) != v:
                        last_change = time.monotonic()
                    pose[key] = v
            got.append((frame.name, values))
        for b, bus in enumerate(buses):
            while (msg := bus.recv(timeout=0)) is not None:
                cob = msg.arbitration_id
                if cob == SYNC and b == 0:
                    syncs += 1
                    continue
                cable = node_cable.get((b, cob & 0x7F))
                if cable is None or len(msg.data) != 6 or (cob & ~0x7F) not in (TPDO1, RPDO1):
                    continue
                value = struct.unpack_from("<i", bytes(msg.data), 2)[0]
                into = actual if (cob & ~0x7F) == TPDO1 else target
                if into[cable] != value:
                    last_change = time.monotonic()
                into[cable] = value
        return got

    deadline = time.monotonic() + args.deadline

    def wait(what, condition):
        while time.monotonic() < deadline:
            for item in poll():
                if condition(item):
                    return item
            if condition(None):
                return None
            # Each poll is a system call per bus, slow in the guest; the
            # sockets hold many cycles' frames.
            time.sleep(0.05)
        fail(f"timed out waiting for {what}")

    wait("STATUS in RUN", lambda item: state == RUN)
    # The guest's cycle rate, from the SYNCs the manager sends on bus 0.
    syncs, start = 0, time.monotonic()
    wait("a measurement window", lambda item: time.monotonic() - start >= 5)
    say(f"SYNCs on {config['buses'][0]}: {syncs / (time.monotonic() - start):.1f}/s")

    x, y, z = args.target.split()
    report = None
    # A target refused (not RUN for a moment: a stale cycle) is sent again.
    for attempt in range(4):
        sequence = (args.sequence + attempt) & 0xFF
        sent_s = time.monotonic()
        host.send(message("TARGET_POSITION_XY", {"X": x, "Y": y}))
        host.send(message("TARGET_POSITION_Z", {"Z": z, "MODE": 0, "TRACKING": 0, "REFUSE_EXTRAPOLATING": 0,
                                                 "SEQUENCE": sequence}))
        item = wait(f"IK_REPORT {sequence}", lambda item: item is not None and item[0] == "IK_REPORT" and
                    int(item[1]["SEQUENCE"]) == sequence and int(item[1]["OUTCOME"]) != IN_PROGRESS)
        report = item[1]
        say(f"target {sequence}: IK_REPORT outcome {int(report['OUTCOME'])}, {int(report['ITERATIONS'])} iterations, "
            f"{int(report['CYCLES'])} cycles, residual {float(report['POSITION_RESIDUAL']):.3f} mm, "
            f"after {time.monotonic() - sent_s:.2f} s")
        if int(report["OUTCOME"]) == CONVERGED:
            break
    else:
        fail("the target did not converge")

    moved_s = time.monotonic()

    def settled(item):
        if state != RUN or None in actual or None in target or any(abs(a - t) > SETTLED_COUNTS for a, t in zip(actual, target)):
            return False
        return time.monotonic() - last_change >= STILL_SECONDS

    wait("every drive on its setpoint, the pose still", settled)
    say(f"drives on their setpoints and still {time.monotonic() - moved_s:.1f} s after the report")
    if state != RUN:
        fail(f"STATUS STATE {state} once still")  # the wait above ends only in RUN
    # The setpoints the drives reached are the target's solution: the pose of
    # their positions is the target, to the residual and the bus's 0.01 mm.
    reached_mm = math.dist([float(pose[k]) for k in ("POSE_POSITION_XY_X", "POSE_POSITION_XY_Y", "POSE_POSITION_Z_Z")],
                           [float(v) for v in (x, y, z)])
    say(f"the still pose is {reached_mm:.4f} mm from the target")
    if not reached_mm <= 0.02 + float(report["POSITION_RESIDUAL"]):
        fail(f"the still pose is {reached_mm:.4f} mm from the target")

    # Cable length = position / (counts_per_mm * direction) + homing_offset_mm
    # (tools/cli/drives_config.hpp).
    lengths = [0.0] * len(drives)
    for d in drives:
        lengths[d["cable"]] = actual[d["cable"]] / (d["counts_per_mm"] * d["direction"]) + d["homing_offset_mm"]
    segments = len(drives) // 4
    with open(args.cables, "w") as out:
        out.write(",".join(f"l{s + 1}_{k + 1}" for s in range(segments) for k in range(4)) + "\n")
        out.write(",".join(f"{v:.6f}" for v in lengths) + "\n")
    with open(args.pose, "w") as out:
        out.write(" ".join(str(pose[k]) for k in ("POSE_POSITION_XY_X", "POSE_POSITION_XY_Y", "POSE_POSITION_Z_Z",
                                                  "POSE_ORIENTATION_QW", "POSE_ORIENTATION_QX", "POSE_ORIENTATION_QY",
                                                  "POSE_ORIENTATION_QZ")) + "\n")
    say("final counts " + " ".join(str(a) for a in actual))


def compare(args):
    with open(args.pose) as f:
        published = [float(v) for v in f.read().split()]
    with open(args.replay) as f:
        lines = [line for line in f.read().splitlines() if line and not line.startswith("#")]
    header = lines[0].split(",")
    row = dict(zip(header, (float(v) for v in lines[-1].split(","))))
    replayed = [row[k] for k in ("x", "y", "z", "qw", "qx", "qy", "qz")]
    distance = math.dist(published[:3], replayed[:3])
    # The bus carries the position in 0.01 mm: at most 0.0087 mm of the
    # difference is the published pose's rounding.
    dot = abs(sum(a * b for a, b in zip(published[3:], replayed[3:])))
    norm = math.sqrt(sum(a * a for a in published[3:]))
    angle = 2 * math.acos(min(1.0, dot / norm))
    say(f"published pose {published[:3]} vs replay {replayed[:3]}: {distance:.4f} mm, {angle:.2e} rad")
    if not distance <= args.tolerance:
        fail(f"the published pose is {distance:.4f} mm from the replay (limit {args.tolerance} mm)")
    # POSE_ORIENTATION is in steps of 3.05e-5: a few of them.
    if not angle <= 2e-4:
        fail(f"the published orientation is {angle:.2e} rad from the replay's")


def main():
    parser = argparse.ArgumentParser()
    commands = parser.add_subparsers(dest="command", required=True)
    m = commands.add_parser("move")
    m.add_argument("--dbc", required=True)
    m.add_argument("--config", required=True)
    m.add_argument("--target", required=True)
    m.add_argument("--cables", required=True)
    m.add_argument("--pose", required=True)
    m.add_argument("--sequence", type=int, default=0x31)
    m.add_argument("--deadline", type=float, default=180.0)
    c = commands.add_parser("compare")
    c.add_argument("--pose", required=True)
    c.add_argument("--replay", required=True)
    c.add_argument("--tolerance", type=float, default=0.01)
    args = parser.parse_args()
    move(args) if args.command == "move" else compare(args)


if __name__ == "__main__":
    main()
