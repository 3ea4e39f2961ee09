#!/usr/bin/python3
"""The CAN FD bus test's client: the drives and the host of cdcr-runtime on
vcan, written with python-can (FD frames, bit-rate switch) and the protocol's
FD DBC read by canmatrix, so nothing of the project's codec is in it.

  fd_client.py --dbc cdcr_fd.dbc --values values.txt --host vcan0
               [--drives vcan1] --summary out.txt [--poses N] [--deadline S]

Every period it sends each segment's CABLE_FEEDBACK (on the drives' bus) and
a streamed TARGET_FD (TRACKING, a new SEQUENCE each time, on the host's
bus); with two buses it also sends on the host's bus a CABLE_FEEDBACK 5 mm
off, which the runtime must not take. It keeps every frame it receives, and
at the end decodes each with the DBC: an identifier the DBC lacks, a frame
of another format or length than the DBC's, or one that does not decode
fails the test. The compensated poses and the last setpoints go to the
summary, which socketcan_check fd-check compares with the model library.

It stops once it has received N POSE_FD frames (200) and N / 4 setpoint
frames, not after a fixed time: inside User-Mode Linux neither side holds
its period, and a busy host slows both. Past the deadline (120 s) it fails.
"""

import argparse
import decimal
import logging
import os
import sys
import time
from collections import Counter

import can
import canmatrix.formats

# Frames the runtime sends on an FD bus, and where (two buses: the pose,
# STATUS, STATS and the reports to the host; the setpoints to the drives).
HOST_FRAMES = {"POSE_FD", "STATUS", "STATS", "IK_REPORT"}
DRIVES_FRAMES = {"CABLE_SETPOINTS_FD_0"}
CLASSICAL_ONLY = {"POSE_POSITION_XY", "POSE_POSITION_Z", "POSE_ORIENTATION", "POSE_UNCERTAINTY"}
RUN = 1  # STATUS STATE


def fail(message):
    print(f"fd_client: FAILED: {message}", flush=True)
    sys.exit(1)


def read_values(path):
    values = {}
    with open(path) as lines:
        for line in lines:
            key, _, value = line.strip().partition("=")
            if key:
                values[key] = value
    return values


# canmatrix's Frame.encode packs raw values: each physical value goes
# through its signal's phys2raw first (exact in Decimal for values on the
# signal's grid, such as lengths in 0.01 mm).
def message(frame, signals):
    raw = {}
    for name, value in signals.items():
        signal = frame.signal_by_name(name)
        if signal is None:
            fail(f"{frame.name} has no signal {name}")
        raw[name] = signal.phys2raw(decimal.Decimal(value))
    data = bytes(frame.encode(raw))
    return can.Message(arbitration_id=frame.arbitration_id.id, data=data, is_extended_id=False, is_fd=frame.is_fd,
                       bitrate_switch=True)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--dbc", required=True)
    parser.add_argument("--values", required=True)
    parser.add_argument("--host", required=True)
    parser.add_argument("--drives")
    parser.add_argument("--poses", type=int, default=200)
    parser.add_argument("--deadline", type=float, default=120.0)
    parser.add_argument("--period-ms", type=float, default=1.0)
    parser.add_argument("--summary", required=True)
    args = parser.parse_args()
    logging.getLogger("canmatrix").setLevel(logging.ERROR)

    database = next(iter(canmatrix.formats.loadp(args.dbc).values()))
    if not all(frame.is_fd for frame in database.frames):
        fail(f"{args.dbc}: not every frame is an FD frame")
    values = read_values(args.values)
    segments = int(values["SEGMENTS"])

    def frame_named(name):
        frame = database.frame_by_name(name)
        if frame is None:
            fail(f"{name} is not in {args.dbc}")
        return frame

    feedback = []
    decoys = []
    for s in range(segments):
        lengths = values[f"FEEDBACK_MM_{s}"].split()
        frame = frame_named(f"CABLE_FEEDBACK_{s}")
        feedback.append(message(frame, {f"L{k + 1}": lengths[k] for k in range(4)}))
        decoys.append(message(frame, {f"L{k + 1}": str(decimal.Decimal(lengths[k]) + 5) for k in range(4)}))
    target_frame = frame_named("TARGET_FD")
    x, y, z = values["TARGET_MM"].split()

    def target_message(sequence):
        return message(target_frame, {
            "TARGET_ORIENTATION_QW": "0", "TARGET_ORIENTATION_QX": "0", "TARGET_ORIENTATION_QY": "0",
            "TARGET_ORIENTATION_QZ": "0", "TARGET_POSITION_XY_X": x, "TARGET_POSITION_XY_Y": y,
            "TARGET_POSITION_Z_Z": z, "TARGET_POSITION_Z_MODE": "0", "TARGET_POSITION_Z_TRACKING": "1",
            "TARGET_POSITION_Z_REFUSE_EXTRAPOLATING": "0", "TARGET_POSITION_Z_SEQUENCE": str(sequence)})

    # Encoded before the loop: canmatrix's packing is too slow for a period.
    targets = [target_message(sequence) for sequence in range(256)]

    host = can.Bus(interface="socketcan", channel=args.host, fd=True)
    drives = can.Bus(interface="socketcan", channel=args.drives, fd=True) if args.drives else host
    buses = [("host", host)] + ([("drives", drives)] if args.drives else [])
    received = []
    sent = 0
    full = 0
    period = args.period_ms / 1000.0
    start = time.monotonic()
    deadline = start + args.deadline
    next_send = start
    pose_id = frame_named("POSE_FD").arbitration_id.id
    setpoints_id = frame_named("CABLE_SETPOINTS_FD_0").arbitration_id.id
    pose_frames = setpoint_frames = 0
    periods = 0

    def send(bus, msg):
        nonlocal sent, full
        try:
            bus.send(msg, timeout=0.01)
            sent += 1
        except can.CanError:
            full += 1  # a full transmit queue in a starved guest: the next period sends again

    while pose_frames < args.poses or 4 * setpoint_frames < args.poses:
        now = time.monotonic()
        if now > deadline:
            fail(f"{pose_frames} POSE_FD and {setpoint_frames} setpoint frames in {args.deadline} s")
        if now >= next_send:
            for msg in feedback:
                send(drives, msg)
            if args.drives:
                send(host, decoys[periods % segments])
            send(host, targets[periods % 256])
            periods += 1
            next_send = max(next_send + period, now)
        for name, bus in buses:
            while (msg := bus.recv(timeout=0)) is not None:
                received.append((name, msg))
                pose_frames += msg.arbitration_id == pose_id
                setpoint_frames += msg.arbitration_id == setpoints_id
        time.sleep(max(0.0, next_send - time.monotonic()))
    seconds = time.monotonic() - start
    for _, bus in buses:
        bus.shutdown()

    counts = Counter()
    poses = []
    setpoints = None
    states = Counter()
    for bus_name, msg in received:
        frame = database.frame_by_id(canmatrix.ArbitrationId(msg.arbitration_id))
        where = f"{bus_name} {msg.arbitration_id:#05x}"
        if frame is None:
            fail(f"{where}: an identifier the DBC does not describe")
        if not msg.is_fd or msg.is_fd != frame.is_fd:
            fail(f"{where} {frame.name}: not an FD frame")
        if not msg.bitrate_switch:
            fail(f"{where} {frame.name}: no bit-rate switch on an fd-brs bus")
        if len(msg.data) != frame.size:
            fail(f"{where} {frame.name}: {len(msg.data)} bytes, the DBC says {frame.size}")
        try:
            decoded = {name: signal.raw_value for name, signal in frame.decode(bytes(msg.data)).items()}
            physical = {name: signal.phys_value for name, signal in frame.decode(bytes(msg.data)).items()}
        except Exception as error:  # canmatrix raises several kinds
            fail(f"{where} {frame.name}: does not decode: {error}")
        counts[(bus_name, frame.name)] += 1
        if frame.name in CLASSICAL_ONLY:
            fail(f"{where} {frame.name}: a classical pose frame on an FD bus")
        if args.drives:
            expected_bus = "host" if frame.name in HOST_FRAMES else "drives" if frame.name in DRIVES_FRAMES else None
            if expected_bus != bus_name:
                fail(f"{where} {frame.name}: on the wrong bus")
        if frame.name == "STATUS":
            states[int(decoded["STATE"])] += 1
        elif frame.name == "POSE_FD" and int(decoded["POSE_POSITION_Z_FLAGS"]) & 1:
            poses.append([physical[f"POSE_POSITION_XY_{a}"] for a in "XY"] + [physical["POSE_POSITION_Z_Z"]] +
                         [physical[f"POSE_ORIENTATION_Q{a}"] for a in "WXYZ"])
        elif frame.name == "CABLE_SETPOINTS_FD_0":
            setpoints = [physical[f"CABLE_SETPOINT_{k}_L{i + 1}"] for k in range(segments) for i in range(4)]

    print(f"fd_client: sent {sent} frames ({periods} periods of {args.period_ms} ms asked, in {seconds:.1f} s; {full} refused by a full queue), received "
          f"{len(received)}, every one decoded; " + ", ".join(f"{b} {n} {c}" for (b, n), c in sorted(counts.items())),
          flush=True)
    print(f"fd_client: STATUS states {dict(states)}", flush=True)
    if states[RUN] == 0:
        fail("no STATUS in RUN")
    if len(poses) < args.poses // 2:
        fail(f"{len(poses)} compensated POSE_FD frames of {pose_frames}, fewer than half")
    if setpoints is None:
        fail("no CABLE_SETPOINTS_FD_0")
    temporary = args.summary + ".tmp"
    with open(temporary, "w") as out:
        for pose in poses:
            out.write("pose " + " ".join(str(v) for v in pose) + "\n")
        out.write("setpoints " + " ".join(str(v) for v in setpoints) + "\n")
    os.replace(temporary, args.summary)


if __name__ == "__main__":
    main()
