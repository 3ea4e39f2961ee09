#!/usr/bin/python3
"""The host of cdcr-runtime in the CiA 402 test on vcan (uml_runtime_test.sh),
written with python-can and the protocol's DBC read by canmatrix, so none of
the project's codec is in it. It also listens on the drives' buses, where it
reads the manager's RPDO1 (target position) and the drives' TPDO1 (position
actual value) straight from the CiA 402 objects' bytes.

  uml_host_peer.py targets --dbc cdcr.dbc --config drives.json --targets FILE
                   --cables out.csv --poses out.txt [--deadline S]
      sends each pose target of FILE (lines POSE_TARGET_k=x y z qw qx qy qz)
      in turn, waits for its IK_REPORT (converged), then for every drive to
      sit on its setpoint and the pose to hold still, and checks that pose
      against the target; writes the drives' still positions as cable
      lengths (dataset CSV, a row per target) and each still pose.
  uml_host_peer.py fault --dbc cdcr.dbc --config drives.json --code N --node K
                   [--recover] [--deadline S]
      waits for STATUS in FAULT with fault N and STATS FAULT_DETAIL K (the
      drive's node id), then with --recover sends DRIVES_COMMAND recover and
      waits for RUN with every drive's position coming again.
  uml_host_peer.py compare --poses out.txt --replay replay.csv [--tolerance MM]
      each published still pose against cdcr-runtime --replay of its lengths.
"""

import argparse
import decimal
import json
import logging
import math
import struct
import sys
import time

RUN, FAULT = 1, 3  # STATUS STATE
CONVERGED, IN_PROGRESS = 0, 6  # IK_REPORT OUTCOME
TPDO1, RPDO1, SYNC = 0x180, 0x200, 0x080
# CiA 402 drives report 0x6041 bit 10 within 10 counts; the check is tighter:
# the simulated loop settles on the target itself once the ramp has ended.
SETTLED_COUNTS = 1
STILL_SECONDS = 3.0
POSE_KEYS = ("POSE_POSITION_XY_X", "POSE_POSITION_XY_Y", "POSE_POSITION_Z_Z", "POSE_ORIENTATION_QW",
             "POSE_ORIENTATION_QX", "POSE_ORIENTATION_QY", "POSE_ORIENTATION_QZ")


def fail(message):
    print(f"uml_host_peer: FAILED: {message}", flush=True)
    sys.exit(1)


def say(message):
    print(f"uml_host_peer: {message}", flush=True)


class Peer:
    """The host's bus and the drives' buses, decoded as they come."""

    def __init__(self, args):
        import can
        logging.getLogger("canmatrix").setLevel(logging.ERROR)  # before its import: it logs the formats it lacks
        import canmatrix.formats
        self.can = can
        database = next(iter(canmatrix.formats.loadp(args.dbc).values()))
        self.frames = {f.arbitration_id.id: f for f in database.frames}
        self.by_name = {f.name: f for f in database.frames}
        with open(args.config) as f:
            self.config = json.load(f)
        self.drives = self.config["drives"]
        self.host = can.Bus(interface="socketcan", channel="vcan0")
        self.buses = [can.Bus(interface="socketcan", channel=name) for name in self.config["buses"]]
        self.node_cable = {(d["bus"], d["node"]): d["cable"] for d in self.drives}
        self.actual = [None] * len(self.drives)
        self.target = [None] * len(self.drives)
        self.pose = {}
        self.state = None
        self.fault = None
        self.fault_detail = None
        self.syncs = 0
        self.last_change = time.monotonic()
        self.deadline = time.monotonic() + args.deadline

    def send(self, name, signals):
        frame = self.by_name[name]
        raw = {k: frame.signal_by_name(k).phys2raw(decimal.Decimal(str(v))) for k, v in signals.items()}
        self.host.send(self.can.Message(arbitration_id=frame.arbitration_id.id, data=bytes(frame.encode(raw)),
                                        is_extended_id=False))

    def poll(self):
        got = []
        while (msg := self.host.recv(timeout=0)) is not None:
            frame = self.frames.get(msg.arbitration_id)
            if frame is None:
                continue
            values = {k: s.phys_value for k, s in frame.decode(bytes(msg.data)).items()}
            if frame.name == "STATUS":
                self.state = int(values["STATE"])
                self.fault = int(values["FAULT"])
                # A stale cycle (FAULT for a moment on a slow guest) restarts the wait for stillness.
                if self.state != RUN:
                    self.last_change = time.monotonic()
            elif frame.name == "STATS":
                self.fault_detail = int(values["FAULT_DETAIL"])
            elif frame.name.startswith("POSE_") and frame.name != "POSE_UNCERTAINTY":
                for k, v in values.items():
                    if k == "SEQUENCE":  # new with every pose
                        continue
                    key = f"{frame.name}_{k}"
                    if self.pose.get(key) != v:
                        self.last_change = time.monotonic()
                    self.pose[key] = v
            got.append((frame.name, values))
        for b, bus in enumerate(self.buses):
            while (msg := bus.recv(timeout=0)) is not None:
                cob = msg.arbitration_id
                if cob == SYNC and b == 0:
                    self.syncs += 1
                    continue
                cable = self.node_cable.get((b, cob & 0x7F))
                if cable is None or len(msg.data) != 6 or (cob & ~0x7F) not in (TPDO1, RPDO1):
                    continue
                value = struct.unpack_from("<i", bytes(msg.data), 2)[0]
                into = self.actual if (cob & ~0x7F) == TPDO1 else self.target
                if into[cable] != value:
                    self.last_change = time.monotonic()
                into[cable] = value
        return got

    def wait(self, what, condition):
        while time.monotonic() < self.deadline:
            for item in self.poll():
                if condition(item):
                    return item
            if condition(None):
                return None
            # Each poll is a system call per bus, slow in the guest; the
            # sockets hold many cycles' frames.
            time.sleep(0.05)
        fail(f"timed out waiting for {what}")

    def settled(self, item=None):
        if self.state != RUN or None in self.actual or None in self.target or \
                any(abs(a - t) > SETTLED_COUNTS for a, t in zip(self.actual, self.target)):
            return False
        return time.monotonic() - self.last_change >= STILL_SECONDS

    def lengths(self):
        # Cable length = position / (counts_per_mm * direction) + homing_offset_mm
        # (tools/cli/drives_config.hpp).
        lengths = [0.0] * len(self.drives)
        for d in self.drives:
            lengths[d["cable"]] = self.actual[d["cable"]] / (d["counts_per_mm"] * d["direction"]) + d["homing_offset_mm"]
        return lengths


def quaternion_angle(a, b):
    dot = abs(sum(x * y for x, y in zip(a, b)))
    norm = math.sqrt(sum(x * x for x in a)) * math.sqrt(sum(x * x for x in b))
    return 2 * math.acos(min(1.0, dot / norm))


def send_target(peer, number, target, sequence):
    """One pose target until it converges (a target refused while not RUN for
    a moment, a stale cycle, is sent again); its final IK_REPORT."""
    x, y, z, qw, qx, qy, qz = target
    for attempt in range(4):
        seq = (sequence + attempt) & 0xFF
        sent_s = time.monotonic()
        peer.send("TARGET_ORIENTATION", {"QW": qw, "QX": qx, "QY": qy, "QZ": qz})
        peer.send("TARGET_POSITION_XY", {"X": x, "Y": y})
        peer.send("TARGET_POSITION_Z", {"Z": z, "MODE": 1, "TRACKING": 0, "REFUSE_EXTRAPOLATING": 0, "SEQUENCE": seq})
        item = peer.wait(f"IK_REPORT {seq}", lambda item: item is not None and item[0] == "IK_REPORT" and
                         int(item[1]["SEQUENCE"]) == seq and int(item[1]["OUTCOME"]) != IN_PROGRESS)
        report = item[1]
        say(f"target {number} (sequence {seq}): IK_REPORT outcome {int(report['OUTCOME'])}, "
            f"{int(report['ITERATIONS'])} iterations, {int(report['CYCLES'])} cycles, residual "
            f"{float(report['POSITION_RESIDUAL']):.3f} mm, after {time.monotonic() - sent_s:.2f} s")
        if int(report["OUTCOME"]) == CONVERGED:
            return report
    fail(f"target {number} did not converge")


def targets(args):
    peer = Peer(args)
    with open(args.targets) as f:
        goals = [[float(v) for v in line.split("=", 1)[1].split()] for line in f if line.startswith("POSE_TARGET_")]
    if len(goals) < 1 or any(len(g) != 7 for g in goals):
        fail(f"{args.targets}: expected lines POSE_TARGET_k=x y z qw qx qy qz")
    peer.wait("STATUS in RUN", lambda item: peer.state == RUN)
    # The guest's cycle rate, from the SYNCs the manager sends on bus 0.
    peer.syncs, start = 0, time.monotonic()
    peer.wait("a measurement window", lambda item: time.monotonic() - start >= 5)
    say(f"SYNCs on {peer.config['buses'][0]}: {peer.syncs / (time.monotonic() - start):.1f}/s")

    rows, poses = [], []
    for number, goal in enumerate(goals):
        report = send_target(peer, number, goal, 0x30 + 4 * number)
        moved_s = time.monotonic()
        peer.wait(f"target {number}: every drive on its setpoint, the pose still", peer.settled)
        pose = [float(peer.pose[k]) for k in POSE_KEYS]
        # The setpoints the drives reached are the target's solution: the
        # pose of their positions is the target, to the residual and the
        # bus's 0.01 mm (position) and Q15 steps (orientation).
        reached_mm = math.dist(pose[:3], goal[:3])
        reached_rad = quaternion_angle(pose[3:], goal[3:])
        say(f"target {number}: still {time.monotonic() - moved_s:.1f} s after the report, {reached_mm:.4f} mm and "
            f"{reached_rad:.2e} rad from the target")
        if not reached_mm <= 0.02 + float(report["POSITION_RESIDUAL"]):
            fail(f"target {number}: the still pose is {reached_mm:.4f} mm from the target")
        if not reached_rad <= 1e-3 + float(report["ORIENTATION_RESIDUAL"]):
            fail(f"target {number}: the still orientation is {reached_rad:.2e} rad from the target")
        rows.append(peer.lengths())
        poses.append(pose)
    segments = len(peer.drives) // 4
    with open(args.cables, "w") as out:
        out.write(",".join(f"l{s + 1}_{k + 1}" for s in range(segments) for k in range(4)) + "\n")
        for row in rows:
            out.write(",".join(f"{v:.6f}" for v in row) + "\n")
    with open(args.poses, "w") as out:
        for pose in poses:
            out.write(" ".join(repr(v) for v in pose) + "\n")


def fault(args):
    peer = Peer(args)
    started_s = time.monotonic()
    # STATS follows its STATUS, and FAULT_DETAIL is typed by that STATUS's FAULT.
    peer.wait(f"STATUS FAULT {args.code} with FAULT_DETAIL {args.node}",
              lambda item: item is not None and item[0] == "STATS" and peer.state == FAULT and
              peer.fault == args.code and peer.fault_detail == args.node)
    say(f"STATUS FAULT {args.code}, FAULT_DETAIL {args.node}: {time.monotonic() - started_s:.2f} s after this peer started")
    if not args.recover:
        return
    # Held in FAULT: nothing brings the runtime back but the command.
    held_s = time.monotonic()
    peer.wait("FAULT held for 2 s", lambda item: time.monotonic() - held_s >= 2 or peer.state != FAULT)
    if peer.state != FAULT:
        fail(f"STATUS STATE {peer.state} before the recover command")
    peer.send("DRIVES_COMMAND", {"COMMAND": 1})
    sent_s = time.monotonic()
    peer.wait("RUN after DRIVES_COMMAND recover", lambda item: peer.state == RUN and peer.fault == 0)
    peer.actual = [None] * len(peer.drives)
    peer.wait("every drive's position again", lambda item: None not in peer.actual)
    say(f"recovered: RUN {time.monotonic() - sent_s:.2f} s after DRIVES_COMMAND")


def compare(args):
    with open(args.poses) as f:
        published = [[float(v) for v in line.split()] for line in f if line.strip()]
    with open(args.replay) as f:
        lines = [line for line in f.read().splitlines() if line and not line.startswith("#")]
    header = lines[0].split(",")
    rows = [dict(zip(header, (float(v) for v in line.split(",")))) for line in lines[1:]]
    if len(rows) != len(published):
        fail(f"{len(published)} still poses but {len(rows)} replayed rows")
    for number, (pose, row) in enumerate(zip(published, rows)):
        replayed = [row[k] for k in ("x", "y", "z", "qw", "qx", "qy", "qz")]
        distance = math.dist(pose[:3], replayed[:3])
        angle = quaternion_angle(pose[3:], replayed[3:])
        say(f"target {number}: published {[round(v, 3) for v in pose[:3]]} vs replay "
            f"{[round(v, 3) for v in replayed[:3]]}: {distance:.4f} mm, {angle:.2e} rad")
        # The bus carries the position in 0.01 mm: at most 0.0087 mm of the
        # difference is the published pose's rounding.
        if not distance <= args.tolerance:
            fail(f"target {number}: the published pose is {distance:.4f} mm from the replay (limit {args.tolerance} mm)")
        # POSE_ORIENTATION is in steps of 3.05e-5: a few of them.
        if not angle <= 2e-4:
            fail(f"target {number}: the published orientation is {angle:.2e} rad from the replay's")


def main():
    parser = argparse.ArgumentParser()
    commands = parser.add_subparsers(dest="command", required=True)
    t = commands.add_parser("targets")
    t.add_argument("--dbc", required=True)
    t.add_argument("--config", required=True)
    t.add_argument("--targets", required=True)
    t.add_argument("--cables", required=True)
    t.add_argument("--poses", required=True)
    t.add_argument("--deadline", type=float, default=400.0)
    f = commands.add_parser("fault")
    f.add_argument("--dbc", required=True)
    f.add_argument("--config", required=True)
    f.add_argument("--code", type=int, required=True)
    f.add_argument("--node", type=int, required=True)
    f.add_argument("--recover", action="store_true")
    f.add_argument("--deadline", type=float, default=60.0)
    c = commands.add_parser("compare")
    c.add_argument("--poses", required=True)
    c.add_argument("--replay", required=True)
    c.add_argument("--tolerance", type=float, default=0.01)
    args = parser.parse_args()
    {"targets": targets, "fault": fault, "compare": compare}[args.command](args)


if __name__ == "__main__":
    main()
