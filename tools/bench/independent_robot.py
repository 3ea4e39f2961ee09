#!/usr/bin/env python3
"""A cable-driven continuum robot that is not the project's simulator.

An independent source of calibration data for the hysteresis work: its own
code, written from the constant-curvature formulas of the kinematics notes
(not from tools/sim), with its own geometry and its own errors:

  - four segments, nominal L = 110 mm and r = 60 mm (the model is told
    these); each real segment differs in length (sigma 1 mm), anchor radius
    (sigma 0.6 mm) and in the angle of its anchor holes (sigma 2 deg), with a
    small twist between segments (sigma 1 deg);
  - a gravity-like sag: each segment bends further towards the horizontal
    part of gravity in its own base frame (the robot mounted at an angle),
    by 0.004 to 0.006 rad times the share of the robot's weight it carries,
    growing to 2.5 times that with its own bend (so it depends on every
    joint before it);
  - the robot's mount in the motion-capture base frame and the marker frame
    on the platform are off by a few millimetres and about a degree;
  - per-cable friction hysteresis as a rate-independent Bouc-Wen model,
    integrated in small steps of the commanded length (RK4, at most
    0.05 mm a step) along every straight move in cable space:
        dz = dx (A - (beta sign(dx z) + gamma) |z|^n),  effective = commanded - z
    with its own A, n, beta / gamma and largest lag
    z_max = (A / (beta + gamma))^(1/n) of 0.3 to 0.9 mm per cable: smooth
    branches whose slope grows from 1 - 2 A beta / (beta + gamma) (0.05 to
    0.4) right after a reversal to 1 - A where z = 0 and to 1 at z_max,
    unlike a play operator's corners;
  - a random repeatability of every achieved bend (sigma 0.001 rad per
    component, about 0.6 mm at the tip: the noise floor of the robot the
    hysteresis figures were first measured on, 0.66 mm with 0.1 mm of
    motion-capture noise);
  - motion-capture noise of 0.1 mm per axis and 0.05 deg per axis.

A session: power-up with unknown friction state, the homing move (every
segment bends 0.1 rad towards alpha = 45 deg, then straight again, straight
lines in cable space), then random configurations (alpha uniform, theta
uniform in [0, 0.2] rad per segment) visited in sequence along straight
lines in cable space. Each row is the commanded cable lengths (the nominal
inverse, eq. 2) and the measured platform pose, with the time the robot
reached it (t_s, seconds from the end of the homing move).

    independent_robot.py --seed 7 --out-dir DIR [--json]

writes DIR/session0.csv (training, 700 rows) and DIR/session1.csv (test,
200 rows: new configurations and noise, the same robot; --effective also
writes the effective lengths in place of the commanded ones, a reference) and prints, per
session: the noise floor (the mean error between the measured poses and the
robot's repeatable ones: what no model can predict, as the simulator
defines it), the motion capture's share alone (true against measured poses),
the tip movement the hysteresis causes (the true poses against the same
commands without friction) and the nominal model's error.

Payload mode (--payload-range LO,HI): every row carries a tip payload drawn
uniform in [LO, HI] kg (a stream of its own: the configurations and noise are
those of the session without it), and each segment bends further by the
payload's weight moment about its base over the segment's bending stiffness
(35 to 48 N m/rad per segment, drawn per seed from a stream of its own),
softening by half from straight to the workspace's largest bend; the sag
moves its own lever arms, solved by fixed-point iteration. The first
kilogram sags the straight robot's tip by 60 to 77 mm. The rows are then
independent samples without cable friction, written as cables, payload_kg,
pose (no t_s: the project takes no time column with a payload). Zero
payload is the robot without one, bit for bit.

The real-like robot (any of --preset, --mechanics, --segments, --length,
--radius, --cables, --collection, --capstan-mu selects it; without them
every file and figure above is unchanged, byte for byte): what makes a real
robot's recordings hard.

  - Geometry: --segments S (default 4), --length L and --radius r (default
    110 and 60 mm), --cables 3 or 4 (default 4) at anchor angles
    psi_j = -(j - 1) 360 deg / c (cable 1 towards alpha = 0; four cables are
    eq. (2)'s); the CSV then has l<s>_1..l<s>_<c>. --preset lab-1seg is the
    lab's robot: 1 segment, L = 64 mm, r = 8 mm, 4 cables, tension
    mechanics. Errors as above, scaled to the size: segment length sigma
    L / 110, anchor radius sigma 1 %, anchor angle sigma 2 deg, twist sigma
    1 deg, mount and marker offsets; no sag.
  - --mechanics lengths (default): the bend is the constant-curvature map of
    the effective lengths. --mechanics tension: the bend and the backbone's
    compression are the static equilibrium of tendon_mechanics.py (elastic
    cables with pretension that go slack under negative stretch, a backbone
    with bending and axial stiffness, cables straight between spacer disks
    every 8 mm), solved numerically for every row. Per seed, at the lab's
    size: cable stiffness k 1.6 to 2.4 N/mm per cable, pretension 0.8 to
    1.2 N, bending stiffness 25 to 35 N mm/rad, axial 2.5 to 3.5 N/mm
    (scaled with r^2 / L and 1 / L for other sizes, so k r^2 against the
    bending stiffness stays the lab's); distal cables get the nominal path
    through the segments before them added to their command.
  - Friction with tension mechanics: capstan friction along the entry guide
    (0.3 rad of wrap) and every spacer disk (its share of the bend), mu 0.15
    to 0.3 per cable (--capstan-mu sets one for all; 0 turns it off): the
    tension reaching the anchor lags the drive's by exp(-+mu phi) according
    to the direction of each cable's last move, a history that grows with
    tension and bend; followed along every move in steps of 2 mm of cable
    travel. Beside it the Bouc-Wen play above on every drive, largest lags
    0.1 to 0.3 mm (0.3 to 0.9 mm with lengths mechanics).
    --no-hysteresis turns both off.
  - Noise with tension mechanics: a repeatability of 0.007 rad per bend
    component at the lab's 64 mm (times 64 mm / (S L) for longer robots:
    0.001 rad at 4 x 110 mm) and 0.1 mm of compression, a tracker's 0.15 mm and 0.1 deg
    per axis (with lengths mechanics 0.001 rad, 0.1 mm and 0.05 deg).
  - --collection consistent (default): random configurations (alpha
    uniform, theta uniform up to 0.2 rad x 60 / r, the four-segment robot's
    12 mm of cable travel, at most 1.2 rad) visited in sequence, timed as
    above. babbling: every cable's
    displacement from its straight length uniform in +-D (--babble-mm,
    default 13), independently, a row every 3.5 s, as the lab's motor
    babbling. repeatability: straight and each pull of --repeat-pulls
    (default 6,12 mm) in --repeat-directions directions (default 8; cable j
    displaced by -p cos(beta - psi_j), the cable towards beta pulled, its
    antagonist released), 17 commands, each reached --repeat-rounds times
    (default 2) from every other one along a random walk that starts and
    ends straight: 544 rows, a row every 3.5 s; --rows is then ignored.
  - The figures add the share of rows bent beyond pi/2 by the
    constant-curvature map of the commands, the spread of the pair sums
    l1 + l3 and l2 + l4 (four cables), and for repeatability runs the
    spread of the same command reached from the same previous one
    (|p_a - p_b| / sqrt(2) over pairs of such visits).
Only numpy; deterministic from the seed.
"""

import argparse
import json
import math
import os
import sys

import numpy as np

import tendon_mechanics

SEGMENTS = 4
NOMINAL_LENGTH_MM = 110.0
NOMINAL_RADIUS_MM = 60.0
WORKSPACE_THETA_MAX_RAD = 0.2
HOMING_BEND_RAD = 0.1
HOMING_ALPHA_RAD = math.pi / 4.0
SESSION_ROWS = (700, 200)
BOUC_WEN_STEP_MM = 0.05
CABLE_SPEED_MM_PER_S = 15.0
DWELL_S = 0.4
GRAVITY_M_PER_S2 = 9.81
# Newton millimetres per radian per segment: the first kilogram at the tip
# sags the straight robot's tip by 60 to 77 mm (the simulator's 75 mm).
PAYLOAD_STIFFNESS_N_MM_PER_RAD = (35000.0, 48000.0)
PAYLOAD_ITERATIONS = 100


# --- constant-curvature kinematics (shared/notes/kinematics-conventions.md) ---

def cable_lengths(alpha, theta, length_mm, radius_mm):
    """Eq. (2): l_j = 2 (L/theta) sin(theta/2) - 2 r cos(alpha + (j-1) pi/2) sin(theta/2)."""
    half = 0.5 * theta
    # 2 (L/theta) sin(theta/2) = L sin(h)/h, exact at theta = 0.
    backbone = length_mm * (math.sin(half) / half if half > 1e-8 else 1.0 - half * half / 6.0)
    return np.array([backbone - 2.0 * radius_mm * math.cos(alpha + j * math.pi / 2.0) * math.sin(half)
                     for j in range(4)])


def joints_from_cables(cables_mm, radius_mm):
    """alpha = atan2(l2 - l4, l3 - l1), theta = 2 asin(hypot(l3 - l1, l4 - l2) / (4 r))."""
    l1, l2, l3, l4 = cables_mm
    alpha = math.atan2(l2 - l4, l3 - l1)
    theta = 2.0 * math.asin(min(1.0, math.hypot(l3 - l1, l4 - l2) / (4.0 * radius_mm)))
    return alpha, theta


def rotation(axis, angle):
    """Rodrigues' formula for a unit axis."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + math.sin(angle) * k + 2.0 * math.sin(0.5 * angle) ** 2 * (k @ k)


def segment_transform(alpha, theta, length_mm):
    """R = Rot((-sin a, cos a, 0), theta), p = (L/theta)((1 - cos t) cos a, (1 - cos t) sin a, sin t)."""
    t = np.eye(4)
    t[:3, :3] = rotation(np.array([-math.sin(alpha), math.cos(alpha), 0.0]), theta)
    if theta > 1e-6:
        # 1 - cos t as 2 sin^2(t/2): no cancellation for small bends.
        in_plane = length_mm * 2.0 * math.sin(0.5 * theta) ** 2 / theta
        along = length_mm * math.sin(theta) / theta
    else:
        in_plane = length_mm * (theta / 2.0 - theta ** 3 / 24.0)
        along = length_mm * (1.0 - theta * theta / 6.0)
    t[:3, 3] = [in_plane * math.cos(alpha), in_plane * math.sin(alpha), along]
    return t


def nominal_pose(cables_mm, length_mm=NOMINAL_LENGTH_MM, radius_mm=NOMINAL_RADIUS_MM):
    """Eq. (13): the product of the segments' transforms, from all 4 N cables."""
    pose = np.eye(4)
    for i in range(len(cables_mm) // 4):
        alpha, theta = joints_from_cables(cables_mm[4 * i:4 * i + 4], radius_mm)
        pose = pose @ segment_transform(alpha, theta, length_mm)
    return pose


def transform(rotation_matrix, translation):
    t = np.eye(4)
    t[:3, :3] = rotation_matrix
    t[:3, 3] = translation
    return t


def quaternion(r):
    """Unit quaternion (w, x, y, z), w >= 0, of a rotation matrix."""
    trace = r[0, 0] + r[1, 1] + r[2, 2]
    if trace > 0.0:
        s = 2.0 * math.sqrt(1.0 + trace)
        q = [0.25 * s, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s]
    elif r[0, 0] > r[1, 1] and r[0, 0] > r[2, 2]:
        s = 2.0 * math.sqrt(1.0 + r[0, 0] - r[1, 1] - r[2, 2])
        q = [(r[2, 1] - r[1, 2]) / s, 0.25 * s, (r[0, 1] + r[1, 0]) / s, (r[0, 2] + r[2, 0]) / s]
    elif r[1, 1] > r[2, 2]:
        s = 2.0 * math.sqrt(1.0 + r[1, 1] - r[0, 0] - r[2, 2])
        q = [(r[0, 2] - r[2, 0]) / s, (r[0, 1] + r[1, 0]) / s, 0.25 * s, (r[1, 2] + r[2, 1]) / s]
    else:
        s = 2.0 * math.sqrt(1.0 + r[2, 2] - r[0, 0] - r[1, 1])
        q = [(r[1, 0] - r[0, 1]) / s, (r[0, 2] + r[2, 0]) / s, (r[1, 2] + r[2, 1]) / s, 0.25 * s]
    q = np.array(q)
    q /= np.linalg.norm(q)
    return -q if q[0] < 0.0 else q


def angle_between_deg(ra, rb):
    cosine = 0.5 * (np.trace(ra.T @ rb) - 1.0)
    return math.degrees(math.acos(max(-1.0, min(1.0, cosine))))


def small_rotation(rng, sigma_rad):
    """A rotation by a normal vector of sigma_rad per axis."""
    v = rng.normal(0.0, sigma_rad, 3)
    angle = np.linalg.norm(v)
    return np.eye(3) if angle == 0.0 else rotation(v / angle, angle)


# --- the homing move --------------------------------------------------------

def homing_waypoints(length_mm=NOMINAL_LENGTH_MM, radius_mm=NOMINAL_RADIUS_MM, segments=SEGMENTS):
    """The approach (every segment bent 0.1 rad towards alpha = 45 deg) and home (straight)."""
    approach = np.concatenate([cable_lengths(HOMING_ALPHA_RAD, HOMING_BEND_RAD, length_mm, radius_mm)
                               for _ in range(segments)])
    home = np.concatenate([cable_lengths(0.0, 0.0, length_mm, radius_mm) for _ in range(segments)])
    return approach, home


# --- friction: rate-independent Bouc-Wen per cable --------------------------

class BoucWen:
    """dz/dx = A - (beta sign(dx z) + gamma) |z|^n per cable; effective = commanded - z."""

    def __init__(self, a, beta, gamma, n):
        self.a, self.beta, self.gamma, self.n = (np.asarray(v, dtype=float) for v in (a, beta, gamma, n))
        self.z = np.zeros_like(self.a)

    def max_lag_mm(self):
        return (self.a / (self.beta + self.gamma)) ** (1.0 / self.n)

    def _slope(self, z, direction):
        return self.a - (self.beta * np.sign(direction * z) + self.gamma) * np.abs(z) ** self.n

    def move(self, start_mm, end_mm):
        """Integrates z along the straight line start -> end in small steps; returns the effective lengths at the end."""
        delta = np.asarray(end_mm, dtype=float) - np.asarray(start_mm, dtype=float)
        steps = max(1, int(math.ceil(np.abs(delta).max() / BOUC_WEN_STEP_MM)))
        h = delta / steps
        z = self.z
        for _ in range(steps):
            k1 = h * self._slope(z, h)
            k2 = h * self._slope(z + 0.5 * k1, h)
            k3 = h * self._slope(z + 0.5 * k2, h)
            k4 = h * self._slope(z + k3, h)
            z = z + (k1 + 2.0 * k2 + 2.0 * k3 + k4) / 6.0
        self.z = z
        return np.asarray(end_mm, dtype=float) - z


# --- the physical robot -------------------------------------------------------

class Robot:
    """The robot's imperfections, drawn once from the seed; ideal=True turns every one off."""

    def __init__(self, seed, ideal=False, hysteresis=True):
        rng = np.random.default_rng([seed, 1000])
        self.ideal = ideal
        self.hysteresis = hysteresis and not ideal
        scale = 0.0 if ideal else 1.0
        self.length_mm = NOMINAL_LENGTH_MM + scale * rng.normal(0.0, 1.0, SEGMENTS)
        self.radius_mm = NOMINAL_RADIUS_MM + scale * rng.normal(0.0, 0.6, SEGMENTS)
        self.anchor_offset_rad = scale * rng.normal(0.0, math.radians(2.0), SEGMENTS)
        self.twist_rad = scale * rng.normal(0.0, math.radians(1.0), SEGMENTS)
        self.base = transform(small_rotation(rng, scale * math.radians(0.7)), scale * rng.normal(0.0, 1.5, 3))
        self.marker = transform(small_rotation(rng, scale * math.radians(1.0)), scale * rng.normal(0.0, 1.0, 3))
        gravity = np.array([-0.8, 0.35, -0.5])
        self.gravity = gravity / np.linalg.norm(gravity)
        self.sag_rad = scale * rng.uniform(0.004, 0.006, SEGMENTS)
        self.repeatability_rad = 0.001 * scale
        self.friction_parameters = bouc_wen_parameters(rng, 4 * SEGMENTS)
        # The segments' bending stiffness under a payload, from a stream of its
        # own so the robot without payload stays the one it always was.
        stiffness_rng = np.random.default_rng([seed, 1001])
        stiffness = stiffness_rng.uniform(*PAYLOAD_STIFFNESS_N_MM_PER_RAD, SEGMENTS)
        self.compliance_rad_per_n_mm = scale / stiffness

    def new_friction(self, rng):
        """The friction state at power-up: anywhere within each cable's range."""
        friction = BoucWen(*self.friction_parameters)
        friction.z = rng.uniform(-1.0, 1.0, friction.a.shape) * friction.max_lag_mm()
        return friction

    def _end_disk(self, effective_mm, bend_noise, payload_bends=None):
        """The end disk's pose, each segment's base frame and commanded bend angle; payload_bends (rad, per
        segment) are added to the achieved bends when given."""
        pose = self.base.copy()
        bases, thetas = [], []
        for i in range(SEGMENTS):
            alpha, theta = joints_from_cables(effective_mm[4 * i:4 * i + 4], self.radius_mm[i])
            bend = theta * np.array([math.cos(alpha + self.anchor_offset_rad[i]),
                                     math.sin(alpha + self.anchor_offset_rad[i])])
            # The sag: towards gravity's part across this segment's base, in
            # proportion to the weight it carries, stiffness falling with bend.
            local_gravity = pose[:3, :3].T @ self.gravity
            carried = (SEGMENTS - i) / SEGMENTS
            bend = bend + self.sag_rad[i] * carried * (1.0 + 1.5 * theta / WORKSPACE_THETA_MAX_RAD) * local_gravity[:2]
            bend = bend + bend_noise[i]
            if payload_bends is not None:
                bend = bend + payload_bends[i]
            bases.append(pose)
            thetas.append(theta)
            pose = pose @ segment_transform(math.atan2(bend[1], bend[0]), float(np.hypot(*bend)), self.length_mm[i])
            pose = pose @ transform(rotation(np.array([0.0, 0.0, 1.0]), self.twist_rad[i]), np.zeros(3))
        return pose, bases, thetas

    def payload_bends(self, end_disk, bases, thetas, payload_kg):
        """Each segment's further bend under the payload hanging at the end disk: the weight's moment about the
        segment's base over its bending compliance, which grows by half from straight to the workspace's
        largest bend (the same softening as the sag of its own weight, milder)."""
        force_n = payload_kg * GRAVITY_M_PER_S2 * self.gravity
        bends = np.zeros((SEGMENTS, 2))
        for i in range(SEGMENTS):
            moment = np.cross(end_disk[:3, 3] - bases[i][:3, 3], force_n)
            local = bases[i][:3, :3].T @ moment
            # A rotation vector (kx, ky, 0) is the bend (theta cos a, theta sin a) = (ky, -kx).
            softening = 1.0 + 0.5 * thetas[i] / WORKSPACE_THETA_MAX_RAD
            bends[i] = np.array([local[1], -local[0]]) * self.compliance_rad_per_n_mm[i] * softening
        return bends

    def loaded_bends(self, effective_mm, bend_noise, payload_kg):
        """The payload's further bends at equilibrium (None without payload): the sag moves its own lever arms,
        so a fixed-point iteration from the unloaded shape."""
        if not (math.isfinite(payload_kg) and payload_kg >= 0.0):
            raise ValueError("payload must be finite and not negative (got {} kg)".format(payload_kg))
        if payload_kg == 0.0:
            return None
        extra = np.zeros((SEGMENTS, 2))
        for _ in range(PAYLOAD_ITERATIONS):
            following = self.payload_bends(*self._end_disk(effective_mm, bend_noise, extra), payload_kg)
            change = np.abs(following - extra).max()
            extra = following
            if change < 1e-12:
                return extra
        raise RuntimeError("payload sag does not converge: {} kg is too heavy for this robot".format(payload_kg))

    def true_pose(self, effective_mm, bend_noise, payload_kg=0.0):
        """The platform's pose in the motion-capture base frame for the lengths that bend the segments, carrying
        payload_kg at the end disk."""
        extra = self.loaded_bends(effective_mm, bend_noise, payload_kg)
        return self._end_disk(effective_mm, bend_noise, extra)[0] @ self.marker

    def straight_sag_mm(self, payload_kg=1.0):
        """How far payload_kg moves the tip of the straight robot (no noise): its first kilogram's sag."""
        home = np.full(4 * SEGMENTS, NOMINAL_LENGTH_MM)
        still = np.zeros((SEGMENTS, 2))
        return float(np.linalg.norm(self.true_pose(home, still, payload_kg)[:3, 3] - self.true_pose(home, still)[:3, 3]))


def random_configuration(rng):
    alphas = rng.uniform(-math.pi, math.pi, SEGMENTS)
    thetas = rng.uniform(0.0, WORKSPACE_THETA_MAX_RAD, SEGMENTS)
    return np.concatenate([cable_lengths(a, t, NOMINAL_LENGTH_MM, NOMINAL_RADIUS_MM) for a, t in zip(alphas, thetas)])


def record_session(robot, seed, session, rows, position_noise_mm=0.1, orientation_noise_deg=0.05,
                   payload_range_kg=None):
    """One session's rows and figures: power-up, homing, then `rows` configurations in sequence. With
    payload_range_kg (lo, hi) every row carries a payload uniform in it, from a stream of its own (the
    configurations and the noise stay those of the session without it)."""
    rng = np.random.default_rng([seed, session])
    payload_rng = np.random.default_rng([seed, session, 2000])
    friction = robot.new_friction(rng)
    # Power-up where the last session left the robot, then the homing move.
    commanded = random_configuration(rng)
    approach, home = homing_waypoints()
    for waypoint in (approach, home):
        if robot.hysteresis:
            friction.move(commanded, waypoint)
        commanded = waypoint
    out = {"t_s": [], "cables": [], "effective": [], "measured": [], "true": [], "repeatable": [],
           "without_hysteresis": [], "payload_kg": [], "without_payload": []}
    t = 0.0
    noise_scale = 0.0 if robot.ideal else 1.0
    for _ in range(rows):
        target = random_configuration(rng)
        effective = friction.move(commanded, target) if robot.hysteresis else target.copy()
        t += np.abs(target - commanded).max() / CABLE_SPEED_MM_PER_S + DWELL_S * rng.uniform(0.8, 1.2)
        commanded = target
        bend_noise = rng.normal(0.0, robot.repeatability_rad, (SEGMENTS, 2))
        payload = 0.0 if payload_range_kg is None else float(payload_rng.uniform(*payload_range_kg))
        true = robot.true_pose(effective, bend_noise, payload)
        measured = true.copy()
        measured[:3, 3] += noise_scale * rng.normal(0.0, position_noise_mm, 3)
        measured[:3, :3] = measured[:3, :3] @ small_rotation(rng, noise_scale * math.radians(orientation_noise_deg))
        out["t_s"].append(round(t, 3))
        out["cables"].append(commanded.copy())
        out["effective"].append(effective.copy())
        out["measured"].append(measured)
        out["true"].append(true)
        out["repeatable"].append(robot.true_pose(effective, np.zeros((SEGMENTS, 2)), payload))
        out["without_hysteresis"].append(robot.true_pose(commanded, bend_noise, payload))
        out["payload_kg"].append(payload)
        out["without_payload"].append(robot.true_pose(effective, bend_noise) if payload > 0.0 else true)
    return out


def mean_errors(poses_a, poses_b):
    position = [np.linalg.norm(a[:3, 3] - b[:3, 3]) for a, b in zip(poses_a, poses_b)]
    orientation = [angle_between_deg(a[:3, :3], b[:3, :3]) for a, b in zip(poses_a, poses_b)]
    return float(np.mean(position)), float(np.mean(orientation)), float(np.max(position))


def pose_fields(pose):
    """A measured pose as the dataset's x,y,z,qw,qx,qy,qz fields."""
    return ["{:.6f}".format(v) for v in pose[:3, 3]] + ["{:.8f}".format(v) for v in quaternion(pose[:3, :3])]


def write_csv(path, data, seed, session, robot, cables="cables", payload=False):
    """The dataset CSV: t_s, cables, pose; with payload the rows are independent samples (the project takes no
    time column with a payload column): cables, payload_kg, pose."""
    names = ([] if payload else ["t_s"]) + ["l{}_{}".format(i + 1, j + 1) for i in range(SEGMENTS) for j in range(4)]
    names += (["payload_kg"] if payload else []) + ["x", "y", "z", "qw", "qx", "qy", "qz"]
    with open(path, "w") as f:
        f.write("# independent robot (tools/bench/independent_robot.py): seed {}, session {}\n".format(seed, session))
        f.write("# nominal geometry: {} segments, L = {} mm, r = {} mm\n".format(
            SEGMENTS, NOMINAL_LENGTH_MM, NOMINAL_RADIUS_MM))
        if payload:
            f.write("# rows are independent samples, each with its tip payload in kg\n")
        else:
            f.write("# rows are a motion sequence after the homing move; t_s in seconds\n")
        f.write("# hysteresis: {}\n".format("Bouc-Wen per cable" if robot.hysteresis else "off"))
        if cables == "effective":
            f.write("# cable columns: the effective lengths (commanded less the friction's lag), for reference\n")
        f.write(",".join(names) + "\n")
        for t, lengths, mass, pose in zip(data["t_s"], data[cables], data["payload_kg"], data["measured"]):
            values = ([] if payload else ["{:.3f}".format(t)]) + ["{:.6f}".format(c) for c in lengths]
            values += ["{:.6f}".format(mass)] if payload else []
            values += pose_fields(pose)
            f.write(",".join(values) + "\n")

# --- the real-like robot: tendon statics, capstan friction, collections ------

# Named geometries: the lab's one-segment robot (four servo-driven cables at
# 90 deg on an 8 mm anchor radius, a 64 mm backbone, a tracker at the tip).
PRESETS = {
    "lab-1seg": {"segments": 1, "length": 64.0, "radius": 8.0, "cables": 4, "mechanics": "tension"},
}
REAL_LIKE_DEFAULTS = {"segments": SEGMENTS, "length": NOMINAL_LENGTH_MM, "radius": NOMINAL_RADIUS_MM, "cables": 4,
                      "mechanics": "lengths"}
# The tendon statics (tension mechanics), per seed within these ranges.
TENDON = {
    "cable_stiffness_n_per_mm": (1.6, 2.4),
    "pretension_n": (0.8, 1.2),
    # Bending stiffness as K_b r^2 / L: the cables' lever against the backbone.
    "bending_n_mm_per_rad_at_lab": (25.0, 35.0),
    "axial_n_per_mm_at_lab": (2.5, 3.5),
    "capstan_mu": (0.15, 0.3),
    "capstan_entry_wrap_rad": 0.3,
    "spacer_pitch_mm": 8.0,
}
# The friction state follows every move in steps of at most this much cable travel.
TENSION_STEP_MM = 2.0
TENSION_HALVINGS = 6
# Bouc-Wen play on the drives of the real-like robot: the lab robot's servo
# horns and cable ends, smaller than the four-segment robot's 0.3 to 0.9 mm.
REAL_LIKE_LAG_MM = (0.1, 0.3)
REAL_LIKE_REPEATABILITY_RAD = 0.007
REAL_LIKE_COMPRESSION_NOISE_MM = 0.1
TRACKER_POSITION_NOISE_MM = 0.15
TRACKER_ORIENTATION_NOISE_DEG = 0.1
# Collections.
BABBLE_MM = 13.0
STEP_S = 3.5
REPEAT_PULLS_MM = (6.0, 12.0)
REPEAT_DIRECTIONS = 8
REPEAT_ROUNDS = 2


def anchor_angles(cables):
    """Cable j (0-based) of a segment at -j 2 pi / c: for four cables the handedness of eq. (2), where cable 1
    lies towards alpha = 0 and cable 4 towards alpha = 90 deg."""
    return np.array([-2.0 * math.pi * j / cables for j in range(cables)])


def cable_lengths_general(alpha, theta, length_mm, radius_mm, cables=4):
    """Eq. (2) for c cables at anchor_angles(c): 2 (L/theta) sin(theta/2) - 2 r cos(alpha - psi_j) sin(theta/2)."""
    half = 0.5 * theta
    backbone = length_mm * (math.sin(half) / half if half > 1e-8 else 1.0 - half * half / 6.0)
    return backbone - 2.0 * radius_mm * np.cos(alpha - anchor_angles(cables)) * math.sin(half)


def joints_from_cables_general(cables_mm, radius_mm):
    """The inverse of cable_lengths_general for c >= 3 cables: the first harmonic of the lengths over the
    anchor angles, (a, b) = (2/c) sum l_j (cos psi_j, sin psi_j) = -2 r sin(theta/2) (cos alpha, sin alpha).
    For four cables, alpha = atan2(l2 - l4, l3 - l1) and theta = 2 asin(hypot(l3 - l1, l4 - l2) / (4 r))."""
    cables_mm = np.asarray(cables_mm, dtype=float)
    psi = anchor_angles(len(cables_mm))
    a = 2.0 / len(cables_mm) * np.dot(cables_mm, np.cos(psi))
    b = 2.0 / len(cables_mm) * np.dot(cables_mm, np.sin(psi))
    alpha = math.atan2(-b, -a)
    theta = 2.0 * math.asin(min(1.0, math.hypot(a, b) / (2.0 * radius_mm)))
    return alpha, theta


def nominal_pose_general(cables_mm, segments, cables, length_mm, radius_mm):
    """Eq. (13) for any cable count: the product of the segments' constant-curvature transforms."""
    pose = np.eye(4)
    for i in range(segments):
        alpha, theta = joints_from_cables_general(cables_mm[cables * i:cables * (i + 1)], radius_mm)
        pose = pose @ segment_transform(alpha, theta, length_mm)
    return pose


def bouc_wen_parameters(rng, count, lag_range_mm=(0.3, 0.9)):
    """Bouc-Wen A, beta, gamma, n per cable with the largest lag uniform in lag_range_mm (the draws and their
    order as the four-segment robot's)."""
    max_lag = rng.uniform(lag_range_mm[0], lag_range_mm[1], count)
    n = rng.uniform(1.0, 2.0, count)
    # Right after a full reversal dz/dx = 2 A beta / (beta + gamma): the
    # effective length's slope there, 1 - 2 A beta / (beta + gamma), must
    # stay positive (the cable end never moves against the drive).
    reversal_slope = rng.uniform(0.05, 0.4, count)
    beta_share = rng.uniform(0.5, 0.85, count)
    a = (1.0 - reversal_slope) / (2.0 * beta_share)
    beta_plus_gamma = a / max_lag ** n
    return a, beta_share * beta_plus_gamma, (1.0 - beta_share) * beta_plus_gamma, n


class RealLikeRobot:
    """A robot of any segment count, cable count and size, drawn once from the seed. mechanics 'lengths': the
    bend is the constant-curvature map of the effective lengths (as the four-segment robot, without its sag);
    'tension': the bend is the statics of tendon_mechanics.Tendons, with capstan friction of mu per cable
    (capstan_mu None: drawn in TENDON["capstan_mu"]; 0: none). ideal=True turns every error off; hysteresis=False the
    Bouc-Wen play and the capstan friction."""

    def __init__(self, seed, segments, cables, length_mm, radius_mm, mechanics="lengths", capstan_mu=None,
                 hysteresis=True, ideal=False):
        if cables < 3:
            raise ValueError("a segment needs at least 3 cables (got {})".format(cables))
        rng = np.random.default_rng([seed, 3000])
        self.segments, self.cables, self.mechanics = segments, cables, mechanics
        self.nominal_length_mm, self.nominal_radius_mm = length_mm, radius_mm
        self.ideal = ideal
        self.hysteresis = hysteresis and not ideal
        scale = 0.0 if ideal else 1.0
        # Manufacturing errors in proportion to the size (the four-segment robot's at L = 110, r = 60).
        self.length_mm = length_mm + scale * rng.normal(0.0, length_mm / 110.0, segments)
        self.radius_mm = radius_mm + scale * rng.normal(0.0, 0.01 * radius_mm, segments)
        self.anchor_offset_rad = scale * rng.normal(0.0, math.radians(2.0), segments)
        self.twist_rad = scale * rng.normal(0.0, math.radians(1.0), segments)
        size = length_mm * segments / (4.0 * 110.0)
        self.base = transform(small_rotation(rng, scale * math.radians(0.7)), scale * size * rng.normal(0.0, 1.5, 3))
        self.marker = transform(small_rotation(rng, scale * math.radians(1.0)), scale * size * rng.normal(0.0, 1.0, 3))
        tension = mechanics == "tension"
        # The lab robot's repeatability at its 64 mm, in proportion for longer robots (0.001 rad at 4 x 110 mm).
        self.repeatability_rad = scale * (REAL_LIKE_REPEATABILITY_RAD * 64.0 / (segments * length_mm) if tension
                                          else 0.001)
        self.compression_noise_mm = scale * REAL_LIKE_COMPRESSION_NOISE_MM if tension else 0.0
        self.position_noise_mm = scale * (TRACKER_POSITION_NOISE_MM if tension else 0.1)
        self.orientation_noise_deg = scale * (TRACKER_ORIENTATION_NOISE_DEG if tension else 0.05)
        count = segments * cables
        self.friction_parameters = bouc_wen_parameters(rng, count, REAL_LIKE_LAG_MM if tension else (0.3, 0.9))
        # The same cable travel as the four-segment robot's workspace (12 mm), at most 1.2 rad.
        self.workspace_theta_max_rad = min(1.2, WORKSPACE_THETA_MAX_RAD * NOMINAL_RADIUS_MM / radius_mm)
        self.tendons = self.frictionless = None
        if tension:
            t_rng = np.random.default_rng([seed, 3001])
            # Stiffness scaled from the lab's robot so the cables' lever k r^2 against K_b stays its own.
            lever = (radius_mm / 8.0) ** 2 * (64.0 / length_mm)
            bending = t_rng.uniform(*TENDON["bending_n_mm_per_rad_at_lab"], segments) * lever
            axial = t_rng.uniform(*TENDON["axial_n_per_mm_at_lab"], segments) * 64.0 / length_mm
            k = t_rng.uniform(*TENDON["cable_stiffness_n_per_mm"], (segments, cables))
            pretension = t_rng.uniform(*TENDON["pretension_n"], (segments, cables))
            if capstan_mu is None:
                mu = t_rng.uniform(*TENDON["capstan_mu"], (segments, cables))
            else:
                mu = np.full((segments, cables), float(capstan_mu))
            if not self.hysteresis:
                mu = np.zeros_like(mu)
            angles = anchor_angles(cables)[None, :] + self.anchor_offset_rad[:, None]
            spans = max(1, int(round(length_mm / TENDON["spacer_pitch_mm"])))
            common = dict(length_mm=self.length_mm, radius_mm=self.radius_mm, anchor_rad=angles,
                          bending_n_mm_per_rad=bending, axial_n_per_mm=axial, cable_n_per_mm=k,
                          pretension_n=pretension, wrap0_rad=TENDON["capstan_entry_wrap_rad"], spans=spans)
            self.tendons = tendon_mechanics.Tendons(mu=mu, **common)
            self.frictionless = tendon_mechanics.Tendons(mu=0.0, **common)
            self.mu = mu

    def new_friction(self, rng):
        """The play's state at power-up: anywhere within each cable's range."""
        friction = BoucWen(*self.friction_parameters)
        friction.z = rng.uniform(-1.0, 1.0, friction.a.shape) * friction.max_lag_mm()
        return friction

    def straight_command(self):
        return np.full(self.segments * self.cables, self.nominal_length_mm)

    def random_configuration(self, rng):
        alphas = rng.uniform(-math.pi, math.pi, self.segments)
        thetas = rng.uniform(0.0, self.workspace_theta_max_rad, self.segments)
        return np.concatenate([cable_lengths_general(a, t, self.nominal_length_mm, self.nominal_radius_mm, self.cables)
                               for a, t in zip(alphas, thetas)])

    def homing_waypoints(self):
        approach = np.concatenate([cable_lengths_general(HOMING_ALPHA_RAD, HOMING_BEND_RAD, self.nominal_length_mm,
                                                         self.nominal_radius_mm, self.cables)
                                   for _ in range(self.segments)])
        return approach, self.straight_command()

    def nominal_pose(self, cables_mm):
        return nominal_pose_general(cables_mm, self.segments, self.cables, self.nominal_length_mm,
                                    self.nominal_radius_mm)

    def rest_lengths(self, effective_mm, tendons=None):
        """The cables' rest lengths for effective drive lengths: cable j of segment i is commanded its length
        in segment i; the drive adds the nominal path through the segments before (the decoupling a controller
        does), less the pretension's stretch."""
        tendons = tendons or self.tendons
        per_segment = np.asarray(effective_mm, dtype=float).reshape(self.segments, self.cables)
        total = per_segment.copy()
        for i in range(1, self.segments):
            for m in range(i):
                alpha, theta = joints_from_cables_general(per_segment[m], self.nominal_radius_mm)
                total[i] += cable_lengths_general(alpha, theta, self.nominal_length_mm, self.nominal_radius_mm,
                                                  self.cables)
        return tendons.rest_lengths(total)

    def state_for(self, effective_mm):
        """Lengths mechanics: (segments x 3) bend vectors from the constant-curvature map, no compression."""
        state = np.zeros((self.segments, 3))
        for i in range(self.segments):
            alpha, theta = joints_from_cables_general(effective_mm[self.cables * i:self.cables * (i + 1)],
                                                      self.radius_mm[i])
            state[i, :2] = theta * np.array([math.cos(alpha + self.anchor_offset_rad[i]),
                                             math.sin(alpha + self.anchor_offset_rad[i])])
        return state

    def pose(self, state, noise):
        """The tip's pose in the tracker's base frame for a state (bend vectors, compressions) and its noise."""
        pose = self.base.copy()
        for i in range(self.segments):
            bend = state[i, :2] + noise[i, :2]
            pose = pose @ segment_transform(math.atan2(bend[1], bend[0]), float(np.hypot(*bend)),
                                            self.length_mm[i] - state[i, 2] - noise[i, 2])
            pose = pose @ transform(rotation(np.array([0.0, 0.0, 1.0]), self.twist_rad[i]), np.zeros(3))
        return pose @ self.marker

    def noise(self, rng):
        out = np.empty((self.segments, 3))
        out[:, :2] = rng.normal(0.0, self.repeatability_rad, (self.segments, 2))
        out[:, 2] = rng.normal(0.0, self.compression_noise_mm, self.segments) if self.compression_noise_mm \
            else 0.0
        return out


class RealLikeMotion:
    """The robot's state along a sequence of commands: the drives' Bouc-Wen play and, with tension mechanics,
    the capstan friction's anchor tensions, followed in steps of at most TENSION_STEP_MM."""

    def __init__(self, robot, rng):
        self.robot = robot
        self.play = robot.new_friction(rng) if robot.hysteresis else None
        self.state = np.zeros((robot.segments, 3))
        self.anchor = None
        self.free_state = np.zeros((robot.segments, 3))

    def move(self, start_mm, end_mm):
        """Moves along the straight line start -> end; returns the effective lengths and the state at the end."""
        r = self.robot
        start_mm, end_mm = np.asarray(start_mm, dtype=float), np.asarray(end_mm, dtype=float)
        if r.tendons is None:
            effective = self.play.move(start_mm, end_mm) if self.play is not None else end_mm.copy()
            self.state = r.state_for(effective)
            return effective, self.state
        steps = max(1, int(math.ceil(np.abs(end_mm - start_mm).max() / TENSION_STEP_MM)))
        previous = start_mm
        rest = r.rest_lengths(self.play.move(start_mm, start_mm) if self.play is not None else start_mm)
        for s in range(1, steps + 1):
            point = start_mm + (end_mm - start_mm) * s / steps
            effective = self.play.move(previous, point) if self.play is not None else point.copy()
            previous = point
            following = r.rest_lengths(effective)
            self._settle(rest, following)
            rest = following
        return effective, self.state

    def _settle(self, rest_from, rest_to, depth=0):
        """The equilibrium at rest_to from the one at rest_from; where Newton's method stalls on a change of
        stick and slip, the step in halves (at most TENSION_HALVINGS times)."""
        try:
            self.state, self.anchor = self.robot.tendons.solve(rest_to, self.state, self.anchor)
        except RuntimeError:
            if depth >= TENSION_HALVINGS:
                raise
            middle = 0.5 * (rest_from + rest_to)
            self._settle(rest_from, middle, depth + 1)
            self._settle(middle, rest_to, depth + 1)

    def without_friction(self, commanded_mm):
        """The state the same command reaches without play or capstan friction."""
        r = self.robot
        if r.tendons is None:
            return r.state_for(np.asarray(commanded_mm, dtype=float))
        self.free_state, _ = r.frictionless.solve(r.rest_lengths(commanded_mm, r.frictionless), self.free_state)
        return self.free_state


def babbling_commands(robot, rng, rows, babble_mm=BABBLE_MM):
    """Each cable's displacement from its straight length uniform in [-D, D], independently, row by row."""
    return [robot.straight_command() + rng.uniform(-babble_mm, babble_mm, robot.segments * robot.cables)
            for _ in range(rows)]


def repeatability_commands(robot, pulls_mm=REPEAT_PULLS_MM, directions=REPEAT_DIRECTIONS):
    """Straight, then each pull in each direction beta: cable j displaced by -p cos(beta - psi_j) in every
    segment (the cable towards beta pulled by p, its antagonist released by as much)."""
    psi = anchor_angles(robot.cables)
    out = [robot.straight_command()]
    for p in pulls_mm:
        for d in range(directions):
            beta = 2.0 * math.pi * d / directions
            out.append(robot.straight_command() + np.tile(-p * np.cos(beta - psi), robot.segments))
    return out


def repeatability_order(count, rounds, rng):
    """A walk over `count` commands from command 0 back to it in which every ordered pair of different commands
    is a step exactly `rounds` times: each command is reached rounds (count - 1) times, from each other command
    `rounds` times. An Eulerian circuit of that multigraph (Hierholzer's algorithm), the edges taken in a
    random order."""
    remaining = []
    for node in range(count):
        edges = [other for other in range(count) if other != node for _ in range(rounds)]
        rng.shuffle(edges)
        remaining.append(edges)
    stack, circuit = [0], []
    while stack:
        node = stack[-1]
        if remaining[node]:
            stack.append(remaining[node].pop())
        else:
            circuit.append(stack.pop())
    circuit.reverse()
    return circuit


def record_real_like(robot, seed, session, rows, collection="consistent", babble_mm=BABBLE_MM,
                     pulls_mm=REPEAT_PULLS_MM, directions=REPEAT_DIRECTIONS, rounds=REPEAT_ROUNDS):
    """One session of the real-like robot: power-up, homing, then the collection's commands in order.
    consistent: `rows` random constant-curvature configurations; babbling: `rows` independent uniform cable
    displacements; repeatability: the commands of repeatability_commands, visited by repeatability_order
    (rows is ignored). Also records, per row, the command before it and its index in the command set."""
    rng = np.random.default_rng([seed, session, 3100])
    motion = RealLikeMotion(robot, rng)
    commanded = robot.random_configuration(rng)
    approach, home = robot.homing_waypoints()
    for waypoint in (approach, home):
        motion.move(commanded, waypoint)
        motion.without_friction(waypoint)
        commanded = waypoint
    command_rng = np.random.default_rng([seed, session, 3200])
    labels = None
    if collection == "consistent":
        targets = [robot.random_configuration(command_rng) for _ in range(rows)]
    elif collection == "babbling":
        targets = babbling_commands(robot, command_rng, rows, babble_mm)
    elif collection == "repeatability":
        commands = repeatability_commands(robot, pulls_mm, directions)
        order = repeatability_order(len(commands), rounds, command_rng)
        labels = order[1:]
        targets = [commands[i] for i in labels]
        previous = order[:-1]
    else:
        raise ValueError("unknown collection '{}'".format(collection))
    out = {"t_s": [], "cables": [], "effective": [], "measured": [], "true": [], "repeatable": [],
           "without_hysteresis": [], "command": labels or [], "previous": previous if labels else []}
    t = 0.0
    for target in targets:
        effective, state = motion.move(commanded, target)
        if collection == "consistent":
            t += np.abs(target - commanded).max() / CABLE_SPEED_MM_PER_S + DWELL_S * rng.uniform(0.8, 1.2)
        else:
            t += STEP_S
        commanded = target
        noise = robot.noise(rng)
        true = robot.pose(state, noise)
        measured = true.copy()
        measured[:3, 3] += rng.normal(0.0, robot.position_noise_mm, 3)
        measured[:3, :3] = measured[:3, :3] @ small_rotation(rng, math.radians(robot.orientation_noise_deg))
        out["t_s"].append(round(t, 3))
        out["cables"].append(commanded.copy())
        out["effective"].append(effective.copy())
        out["measured"].append(measured)
        out["true"].append(true)
        out["repeatable"].append(robot.pose(state, np.zeros_like(noise)))
        out["without_hysteresis"].append(robot.pose(motion.without_friction(commanded), noise))
    return out


def beyond_quarter_turn(cables, robot):
    """The share of rows whose constant-curvature bend (the nominal map of the commands) of any segment
    exceeds pi / 2."""
    c = robot.cables
    beyond = [any(joints_from_cables_general(row[c * i:c * (i + 1)], robot.nominal_radius_mm)[1] > 0.5 * math.pi
                  for i in range(robot.segments)) for row in cables]
    return float(np.mean(beyond))


def pair_sum_spread(cables, robot):
    """Four cables per segment: the range (max - min) of l1 + l3 and of l2 + l4 over the rows, per segment."""
    if robot.cables != 4:
        return None
    table = np.asarray(cables)
    out = []
    for i in range(robot.segments):
        for a, b in ((0, 2), (1, 3)):
            sums = table[:, 4 * i + a] + table[:, 4 * i + b]
            out.append(float(np.ptp(sums)))
    return out


def same_transition_repeatability(data):
    """Repeatability rows: the tip's spread when the same command is reached from the same previous one, as
    the mean over those pairs of visits of |p_a - p_b| / sqrt(2) (the expected distance of one visit from the
    repeatable pose, for independent noise)."""
    groups = {}
    for command, previous, pose in zip(data["command"], data["previous"], data["measured"]):
        groups.setdefault((previous, command), []).append(pose[:3, 3])
    distances = []
    for positions in groups.values():
        for a in range(len(positions)):
            for b in range(a + 1, len(positions)):
                distances.append(np.linalg.norm(positions[a] - positions[b]) / math.sqrt(2.0))
    return float(np.mean(distances)) if distances else float("nan")


def write_real_like_csv(path, data, seed, session, robot, collection, cables="cables"):
    """The dataset CSV of the real-like robot: t_s, l<s>_1..l<s>_<c>, pose."""
    names = ["t_s"] + ["l{}_{}".format(i + 1, j + 1) for i in range(robot.segments) for j in range(robot.cables)]
    names += ["x", "y", "z", "qw", "qx", "qy", "qz"]
    with open(path, "w") as f:
        f.write("# independent robot (tools/bench/independent_robot.py): seed {}, session {}\n".format(seed, session))
        f.write("# nominal geometry: {} segments, L = {} mm, r = {} mm, {} cables per segment\n".format(
            robot.segments, robot.nominal_length_mm, robot.nominal_radius_mm, robot.cables))
        f.write("# mechanics: {}; collection: {}\n".format(robot.mechanics, collection))
        f.write("# rows are a motion sequence after the homing move; t_s in seconds\n")
        friction = "off"
        if robot.hysteresis:
            friction = "Bouc-Wen per cable" + (" and capstan" if robot.tendons is not None and np.any(robot.mu > 0)
                                               else "")
        f.write("# hysteresis: {}\n".format(friction))
        if cables == "effective":
            f.write("# cable columns: the effective lengths (commanded less the friction's lag), for reference\n")
        f.write(",".join(names) + "\n")
        for t, lengths, pose in zip(data["t_s"], data[cables], data["measured"]):
            values = ["{:.3f}".format(t)] + ["{:.6f}".format(c) for c in lengths]
            values += pose_fields(pose)
            f.write(",".join(values) + "\n")



def print_session_figures(s):
    """A session's file and the figures both robots report for it."""
    print("  session {} ({} rows) -> {}".format(s["session"], s["rows"], s["file"]))
    print("    noise floor          {:.3f} mm / {:.4f} deg".format(
        s["noise_floor"]["position_mm"], s["noise_floor"]["orientation_deg"]))
    print("    motion capture alone {:.3f} mm / {:.4f} deg".format(
        s["motion_capture"]["position_mm"], s["motion_capture"]["orientation_deg"]))
    print("    hysteresis moves tip {:.3f} mm mean, {:.3f} mm max".format(
        s["hysteresis_tip_movement_mm"]["mean"], s["hysteresis_tip_movement_mm"]["max"]))
    print("    nominal model error  {:.3f} mm / {:.4f} deg".format(
        s["nominal_error"]["position_mm"], s["nominal_error"]["orientation_deg"]))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", type=int, default=7, help="names the robot and its sessions (default 7)")
    parser.add_argument("--out-dir", required=True, help="writes session0.csv and session1.csv here")
    parser.add_argument("--rows", default="{},{}".format(*SESSION_ROWS), help="rows of session 0 and 1 (default 700,200)")
    parser.add_argument("--no-hysteresis", action="store_true", help="the same robot without cable friction")
    parser.add_argument("--json", action="store_true", help="print the figures as one JSON object")
    parser.add_argument("--report", help="also write the figures as JSON to this file")
    parser.add_argument("--effective", action="store_true",
                        help="also write sessionK.effective.csv: the effective cable lengths (what a model that "
                             "knew the friction exactly would see) in place of the commanded ones")
    parser.add_argument("--payload-range", metavar="LO,HI",
                        help="every row carries a tip payload uniform in [LO, HI] kg, written as payload_kg; the "
                             "rows are then independent samples without t_s and without cable friction")
    real = parser.add_argument_group("the real-like robot (any of these options selects it)")
    real.add_argument("--preset", choices=sorted(PRESETS),
                      help="named geometry and mechanics: lab-1seg is 1 segment, L = 64 mm, r = 8 mm, 4 cables, "
                           "tension mechanics (options given beside it win)")
    real.add_argument("--mechanics", choices=("lengths", "tension"),
                      help="lengths: the bend is the constant-curvature map of the effective cable lengths (the "
                           "default); tension: the statics of elastic tendons against the backbone's bending and "
                           "axial stiffness, with capstan friction")
    real.add_argument("--segments", type=int, help="segments (default 4)")
    real.add_argument("--length", type=float, help="nominal backbone length per segment in mm (default 110)")
    real.add_argument("--radius", type=float, help="nominal anchor radius in mm (default 60)")
    real.add_argument("--cables", type=int, choices=(3, 4),
                      help="cables per segment, at 120 or 90 deg (default 4); columns l<s>_1..l<s>_<c>")
    real.add_argument("--collection", choices=("consistent", "babbling", "repeatability"),
                      help="consistent: random constant-curvature configurations (the default); babbling: every "
                           "cable displaced independently and uniformly within +-D mm; repeatability: a set of "
                           "commands each reached from every other, --repeat-rounds times")
    real.add_argument("--babble-mm", type=float, default=BABBLE_MM,
                      help="babbling: the largest displacement D (default {:g} mm)".format(BABBLE_MM))
    real.add_argument("--repeat-pulls", default=",".join("{:g}".format(p) for p in REPEAT_PULLS_MM),
                      help="repeatability: antagonistic pulls in mm (default 6,12), each in every direction")
    real.add_argument("--repeat-directions", type=int, default=REPEAT_DIRECTIONS,
                      help="repeatability: directions per pull (default 8): with straight, 17 commands")
    real.add_argument("--repeat-rounds", type=int, default=REPEAT_ROUNDS,
                      help="repeatability: how often each command is reached from each other one (default 2: "
                           "32 visits of each of 17 commands, 544 rows; --rows is then ignored)")
    real.add_argument("--capstan-mu", type=float,
                      help="tension mechanics: the capstan friction coefficient of every cable (default: drawn "
                           "per cable in {:g} to {:g}; 0 turns it off)".format(*TENDON["capstan_mu"]))
    args = parser.parse_args(argv)
    if any(getattr(args, name) is not None for name in ("preset", "mechanics", "segments", "length", "radius",
                                                      "cables", "collection", "capstan_mu")):
        return main_real_like(args)
    payload_range = None
    if args.payload_range is not None:
        try:
            payload_range = [float(v) for v in args.payload_range.split(",")]
        except ValueError:
            payload_range = []
        if len(payload_range) != 2 or not all(math.isfinite(v) for v in payload_range) \
                or not 0.0 <= payload_range[0] <= payload_range[1]:
            sys.exit("independent_robot.py: error: --payload-range takes LO,HI in kg with 0 <= LO <= HI, "
                     "not '{}'".format(args.payload_range))
        if args.effective:
            sys.exit("independent_robot.py: error: --effective has no meaning with --payload-range "
                     "(payload rows have no cable friction)")
    try:
        rows = [int(v) for v in args.rows.split(",")]
    except ValueError:
        rows = []
    if len(rows) != 2 or min(rows) < 1:
        sys.exit("independent_robot.py: error: --rows takes two positive counts, e.g. 700,200, not '{}'".format(args.rows))
    os.makedirs(args.out_dir, exist_ok=True)

    robot = Robot(args.seed, hysteresis=not args.no_hysteresis and payload_range is None)
    report = {"seed": args.seed, "hysteresis": robot.hysteresis,
              "max_lag_mm": {"min": float(robot.new_friction(np.random.default_rng(0)).max_lag_mm().min()),
                             "max": float(robot.new_friction(np.random.default_rng(0)).max_lag_mm().max())},
              "sessions": []}
    if payload_range is not None:
        report["payload_range_kg"] = payload_range
        report["straight_tip_sag_mm_first_kg"] = robot.straight_sag_mm(1.0)
    for session, count in enumerate(rows):
        data = record_session(robot, args.seed, session, count, payload_range_kg=payload_range)
        path = os.path.join(args.out_dir, "session{}.csv".format(session))
        write_csv(path, data, args.seed, session, robot, payload=payload_range is not None)
        if args.effective:
            write_csv(os.path.join(args.out_dir, "session{}.effective.csv".format(session)), data, args.seed, session,
                      robot, cables="effective")
        nominal = [nominal_pose(c) for c in data["cables"]]
        motion_capture = mean_errors(data["true"], data["measured"])
        floor = mean_errors(data["repeatable"], data["measured"])
        effect = mean_errors(data["true"], data["without_hysteresis"])
        initial = mean_errors(nominal, data["measured"])
        report["sessions"].append({
            "session": session, "rows": count, "file": path,
            "noise_floor": {"position_mm": floor[0], "orientation_deg": floor[1]},
            "motion_capture": {"position_mm": motion_capture[0], "orientation_deg": motion_capture[1]},
            "hysteresis_tip_movement_mm": {"mean": effect[0], "max": effect[2], "orientation_deg": effect[1]},
            "nominal_error": {"position_mm": initial[0], "orientation_deg": initial[1]},
        })
        if payload_range is not None:
            moved = mean_errors(data["true"], data["without_payload"])
            report["sessions"][-1]["payload_tip_movement_mm"] = {"mean": moved[0], "max": moved[2],
                                                                 "orientation_deg": moved[1]}
    if args.report:
        with open(args.report, "w") as f:
            json.dump(report, f)
    if args.json:
        print(json.dumps(report))
    else:
        print("independent robot, seed {}: cable friction {} (largest lag per cable {:.2f} to {:.2f} mm)".format(
            args.seed, "Bouc-Wen" if robot.hysteresis else "off", report["max_lag_mm"]["min"], report["max_lag_mm"]["max"]))
        if payload_range is not None:
            print("  tip payload {:g} to {:g} kg per row; the first kg sags the straight tip {:.1f} mm".format(
                payload_range[0], payload_range[1], report["straight_tip_sag_mm_first_kg"]))
        for s in report["sessions"]:
            print_session_figures(s)
            if "payload_tip_movement_mm" in s:
                print("    payload moves tip    {:.3f} mm mean, {:.3f} mm max".format(
                    s["payload_tip_movement_mm"]["mean"], s["payload_tip_movement_mm"]["max"]))
    return 0


def main_real_like(args):
    """The real-like robot's sessions, files and figures (the four-segment robot's options where they apply)."""
    def fail(message):
        sys.exit("independent_robot.py: error: " + message)

    settings = dict(REAL_LIKE_DEFAULTS)
    if args.preset:
        settings.update(PRESETS[args.preset])
    for name in settings:
        if getattr(args, name) is not None:
            settings[name] = getattr(args, name)
    collection = args.collection or "consistent"
    if args.payload_range is not None:
        fail("--payload-range is the four-segment robot's only")
    if settings["segments"] < 1 or settings["length"] <= 0.0 or settings["radius"] <= 0.0:
        fail("--segments, --length and --radius must be positive")
    if args.capstan_mu is not None and (settings["mechanics"] != "tension" or not args.capstan_mu >= 0.0):
        fail("--capstan-mu takes a coefficient >= 0 and needs --mechanics tension")
    if not args.babble_mm > 0.0:
        fail("--babble-mm must be positive")
    try:
        pulls = [float(v) for v in args.repeat_pulls.split(",")]
    except ValueError:
        pulls = []
    if not pulls or args.repeat_directions < 1 or args.repeat_rounds < 1:
        fail("--repeat-pulls takes mm values like 6,12; --repeat-directions and --repeat-rounds positive counts")
    try:
        rows = [int(v) for v in args.rows.split(",")]
    except ValueError:
        rows = []
    if len(rows) != 2 or min(rows) < 1:
        fail("--rows takes two positive counts, e.g. 700,200, not '{}'".format(args.rows))
    os.makedirs(args.out_dir, exist_ok=True)
    robot = RealLikeRobot(args.seed, settings["segments"], settings["cables"], settings["length"],
                          settings["radius"], settings["mechanics"], args.capstan_mu, hysteresis=not args.no_hysteresis)
    report = {"seed": args.seed, "hysteresis": robot.hysteresis, "collection": collection,
              "geometry": settings, "sessions": []}
    if robot.tendons is not None:
        report["capstan_mu"] = {"min": float(robot.mu.min()), "max": float(robot.mu.max())}
    for session, count in enumerate(rows):
        data = record_real_like(robot, args.seed, session, count, collection, args.babble_mm, pulls,
                                args.repeat_directions, args.repeat_rounds)
        path = os.path.join(args.out_dir, "session{}.csv".format(session))
        write_real_like_csv(path, data, args.seed, session, robot, collection)
        if args.effective:
            write_real_like_csv(os.path.join(args.out_dir, "session{}.effective.csv".format(session)), data,
                                args.seed, session, robot, collection, cables="effective")
        nominal = [robot.nominal_pose(c) for c in data["cables"]]
        floor = mean_errors(data["repeatable"], data["measured"])
        tracker = mean_errors(data["true"], data["measured"])
        effect = mean_errors(data["true"], data["without_hysteresis"])
        initial = mean_errors(nominal, data["measured"])
        entry = {"session": session, "rows": len(data["cables"]), "file": path,
                 "noise_floor": {"position_mm": floor[0], "orientation_deg": floor[1]},
                 "motion_capture": {"position_mm": tracker[0], "orientation_deg": tracker[1]},
                 "hysteresis_tip_movement_mm": {"mean": effect[0], "max": effect[2], "orientation_deg": effect[1]},
                 "nominal_error": {"position_mm": initial[0], "orientation_deg": initial[1]},
                 "beyond_quarter_turn": beyond_quarter_turn(data["cables"], robot),
                 "pair_sum_spread_mm": pair_sum_spread(data["cables"], robot)}
        if collection == "repeatability":
            entry["same_transition_repeatability_mm"] = same_transition_repeatability(data)
        report["sessions"].append(entry)
    if args.report:
        with open(args.report, "w") as f:
            json.dump(report, f)
    if args.json:
        print(json.dumps(report))
        return 0
    print("independent robot, seed {}: {} segment(s), L = {:g} mm, r = {:g} mm, {} cables, {} mechanics, {}".format(
        args.seed, settings["segments"], settings["length"], settings["radius"], settings["cables"],
        settings["mechanics"], collection))
    for s in report["sessions"]:
        print_session_figures(s)
        print("    beyond pi/2 (constant-curvature map of the commands) {:.1f} %".format(
            100.0 * s["beyond_quarter_turn"]))
        if s["pair_sum_spread_mm"] is not None:
            print("    pair sums' spread    {} mm".format(
                ", ".join("{:.1f}".format(v) for v in s["pair_sum_spread_mm"])))
        if "same_transition_repeatability_mm" in s:
            print("    same command from the same previous one: {:.3f} mm".format(
                s["same_transition_repeatability_mm"]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
