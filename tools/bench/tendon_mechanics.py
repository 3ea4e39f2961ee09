"""The statics of a tendon-driven continuum robot, for independent_robot.py's --mechanics tension.

Each segment m is a backbone of free length L_m and a bend vector
b_m = theta_m (cos alpha_m, sin alpha_m), compressed axially by delta_m.
The robot's cables are elastic tendons: cable j of segment i runs through
the spacer disks of segments 1..i at anchor angle psi_j (radius r_m in
segment m) and is fixed to the end disk of segment i.

  - Path of a cable through segment m, straight between n_m + 1 equally
    spaced disks (n_m spans):
        path = (L_m - delta_m - r_m b_m . u_j) S(|b_m|),  S(q) = sin(q / 2n) / (q / 2n),
    u_j = (cos psi_j, sin psi_j). One span (n = 1) is eq. (2) of the
    kinematics notes; n = None is the continuous offset arc, S = 1.
  - Tension at the drive: T_d = k max(0, sum_m path - rest). The rest
    length is the commanded (effective) length less pretension / k, so the
    straight command holds every cable at its pretension; a cable with
    negative stretch is slack and carries nothing.
  - Capstan friction along the disks: the cable wraps phi_0 at its entry
    guide and theta_m / n_m at each of the n_m disks of every segment m it
    runs through. At each wrap w the tension beyond it, T_out, sticks at its
    last value while T_in e^(-mu w) <= T_out <= T_in e^(mu w) and slides to
    the nearer bound otherwise, from the drive (T_in = T_d) to the anchor
    (T_a, the last). A long pull leaves T_a = T_d e^(-mu phi), a long
    release T_d e^(mu phi), phi = phi_0 + the bends passed; T_a moves only
    once T_d leaves [T_a e^(-mu phi), T_a e^(mu phi)]; a short reversal
    turns only the disks near the drive, so the state remembers more than
    the direction of the last move. The history's size grows with the
    tension and the bend; mu = 0 is no friction.
  - Equilibrium, per segment: the backbone's bending stiffness against the
    moment of every tension crossing it on its anchor radius, and its axial
    stiffness against their sum,
        K_b,m b_m + sum_crossing T_a d path / d b_m = 0,
        K_a,m delta_m + sum_crossing T_a d path / d delta_m = 0,
    which for the continuous arc is K_b theta = r sum T_a cos(alpha - psi_j)
    and K_a delta = sum T_a; without friction it is the stationary point of
    the energy K_b theta^2 / 2 + K_a delta^2 / 2 + sum k max(0, stretch)^2 / 2.
    Solved by damped Newton steps with a finite-difference Jacobian; where
    they stall on a disk between sticking and sliding, by the chord method
    from the guess again (one Jacobian, damped steps). With friction the equilibria of one
    command form a set (the band); the solver returns one of them, near the
    last state.

Only numpy.
"""

import math

import numpy as np

NEWTON_TOLERANCE = 1e-10
NEWTON_ITERATIONS = 200
JACOBIAN_STEP = 1e-7
CHORD_STEP = 1e-4
CHORD_DAMPING = 0.7
CHORD_ITERATIONS = 20000


def span_factor(q, spans):
    """S(q) = sin(q / 2n) / (q / 2n) and dS/dq; S = 1 for the continuous arc (spans None)."""
    if spans is None:
        return 1.0, 0.0
    x = q / (2.0 * spans)
    if x < 1e-4:
        return 1.0 - x * x / 6.0, -x / 3.0 / (2.0 * spans)
    return math.sin(x) / x, (x * math.cos(x) - math.sin(x)) / (x * x) / (2.0 * spans)


class Tendons:
    """One robot's tendon statics. Arrays per segment (length, radius, spans) and per cable (shape segments x
    cables: anchor angles, stiffness, pretension, mu); phi_0 the wrap before the first disk."""

    def __init__(self, length_mm, radius_mm, anchor_rad, bending_n_mm_per_rad, axial_n_per_mm, cable_n_per_mm,
                 pretension_n, mu, wrap0_rad=0.0, spans=None):
        self.length_mm = np.asarray(length_mm, dtype=float)
        self.radius_mm = np.asarray(radius_mm, dtype=float)
        self.anchor_rad = np.asarray(anchor_rad, dtype=float)
        self.segments, self.cables = self.anchor_rad.shape
        self.bending = np.broadcast_to(np.asarray(bending_n_mm_per_rad, dtype=float), (self.segments,))
        self.axial = np.broadcast_to(np.asarray(axial_n_per_mm, dtype=float), (self.segments,))
        shape = (self.segments, self.cables)
        self.k = np.broadcast_to(np.asarray(cable_n_per_mm, dtype=float), shape)
        self.pretension = np.broadcast_to(np.asarray(pretension_n, dtype=float), shape)
        self.mu = np.broadcast_to(np.asarray(mu, dtype=float), shape)
        self.wrap0 = float(wrap0_rad)
        self.spans = spans
        self.u = np.stack([np.cos(self.anchor_rad), np.sin(self.anchor_rad)], axis=-1)
        # The wraps along a cable: the entry, then the disks of each segment in turn.
        self.disks = [1 if spans is None else int(spans)] * self.segments
        self.stages = 1 + sum(self.disks)

    def straight_paths(self):
        """Each cable's path when every segment is straight and uncompressed: sum of L_m up to its segment."""
        return np.repeat(np.cumsum(self.length_mm)[:, None], self.cables, axis=1)

    def rest_lengths(self, cable_paths_mm):
        """The rest lengths of the cables for drive positions given as path lengths (the path the cable would
        fill at its pretension): path - pretension / k."""
        return np.asarray(cable_paths_mm, dtype=float) - self.pretension / self.k

    def _geometry(self, x):
        """Per segment and anchor angle: path, d path / d b (2), d path / d delta; and each segment's bend."""
        b, delta = x[:, :2], x[:, 2]
        paths = np.empty((self.segments, self.cables))
        dpath_db = np.empty((self.segments, self.cables, 2))
        dpath_ddelta = np.empty((self.segments, self.cables))
        bends = np.hypot(b[:, 0], b[:, 1])
        for m in range(self.segments):
            s, ds_dq = span_factor(bends[m], self.spans)
            offset = self.u[m] @ b[m]
            free = self.length_mm[m] - delta[m] - self.radius_mm[m] * offset
            paths[m] = free * s
            ds_db = ds_dq * b[m] / bends[m] if bends[m] > 0.0 else np.zeros(2)
            dpath_db[m] = -self.radius_mm[m] * s * self.u[m] + free[:, None] * ds_db[None, :]
            dpath_ddelta[m] = -s
        return paths, dpath_db, dpath_ddelta, bends

    def wraps(self, bends):
        """The angle each cable wraps at each stage (segments x cables x stages): phi_0, then theta_m / n_m per
        disk of every segment m up to the cable's own, zero beyond it."""
        out = np.zeros((self.segments, self.cables, self.stages))
        out[:, :, 0] = self.wrap0
        first = 1
        for m in range(self.segments):
            out[m:, :, first:first + self.disks[m]] = bends[m] / self.disks[m]
            first += self.disks[m]
        return out

    def tensions(self, x, rest_mm, before=None):
        """Drive tensions (segments x cables) and the tension beyond every stage (segments x cables x stages;
        the last is the anchor's) in state x. before: the stages' tensions of the friction's last state (None:
        no history, the drive's tension everywhere)."""
        paths, _, _, bends = self._geometry(x)
        stretch = np.cumsum(paths, axis=0) - rest_mm
        drive = self.k * np.maximum(0.0, stretch)
        stages = np.repeat(drive[:, :, None], self.stages, axis=2)
        if before is None:
            return drive, stages
        ratio = np.exp(self.mu[:, :, None] * self.wraps(bends))
        inside = drive
        for st in range(self.stages):
            inside = np.clip(before[:, :, st], inside / ratio[:, :, st], inside * ratio[:, :, st])
            stages[:, :, st] = inside
        return drive, stages

    def residual(self, x, rest_mm, before=None):
        """The force balance per segment: bending (N mm, 2) and axial (N)."""
        x = x.reshape(self.segments, 3)
        _, dpath_db, dpath_ddelta, _ = self._geometry(x)
        anchor = self.tensions(x, rest_mm, before)[1][:, :, -1]
        # The tension crossing segment m at angle j: every cable of segment m or beyond.
        crossing = np.cumsum(anchor[::-1], axis=0)[::-1]
        out = np.empty((self.segments, 3))
        out[:, :2] = self.bending[:, None] * x[:, :2] + np.einsum("mj,mjk->mk", crossing, dpath_db)
        out[:, 2] = self.axial * x[:, 2] + np.sum(crossing * dpath_ddelta, axis=1)
        return out.ravel()

    def energy(self, x, rest_mm):
        """The frictionless potential: its gradient is the residual with mu = 0."""
        x = np.asarray(x, dtype=float).reshape(self.segments, 3)
        paths, _, _, bends = self._geometry(x)
        stretch = np.maximum(0.0, np.cumsum(paths, axis=0) - rest_mm)
        return float(0.5 * np.sum(self.bending * bends ** 2) + 0.5 * np.sum(self.axial * x[:, 2] ** 2)
                     + 0.5 * np.sum(self.k * stretch ** 2))

    def _chord(self, x, rest_mm, before):
        """Where Newton's method stalls on a corner of the friction (a disk between sticking and sliding), the
        chord method: damped steps with one Jacobian, by central differences across the corner."""
        f = self.residual(x, rest_mm, before)
        jacobian = np.empty((x.size, x.size))
        for c in range(x.size):
            step = np.zeros_like(x)
            step[c] = CHORD_STEP
            jacobian[:, c] = (self.residual(x + step, rest_mm, before) - self.residual(x - step, rest_mm, before)) \
                / (2.0 * CHORD_STEP)
        inverse = np.linalg.pinv(jacobian)
        for _ in range(CHORD_ITERATIONS):
            if np.linalg.norm(f) < NEWTON_TOLERANCE:
                break
            x = x - CHORD_DAMPING * inverse @ f
            f = self.residual(x, rest_mm, before)
        return x, np.linalg.norm(f)

    def solve(self, rest_mm, start=None, before=None):
        """The equilibrium for the rest lengths: the state (segments x 3: bend vector, compression) and the
        tensions beyond every stage there (segments x cables x stages, the anchor's last: the friction's next
        state). start is the guess (straight by default); before the friction's state (None: none)."""
        rest_mm = np.asarray(rest_mm, dtype=float)
        x = np.zeros(3 * self.segments) if start is None else np.array(start, dtype=float).ravel()
        guess = x.copy()
        f = self.residual(x, rest_mm, before)
        norm = np.linalg.norm(f)
        for _ in range(NEWTON_ITERATIONS):
            if norm < NEWTON_TOLERANCE:
                break
            jacobian = np.empty((x.size, x.size))
            for c in range(x.size):
                step = np.zeros_like(x)
                step[c] = JACOBIAN_STEP
                jacobian[:, c] = (self.residual(x + step, rest_mm, before) - f) / JACOBIAN_STEP
            try:
                dx = -np.linalg.solve(jacobian, f)
            except np.linalg.LinAlgError:
                dx = -np.linalg.lstsq(jacobian, f, rcond=None)[0]
            scale = 1.0
            while True:
                trial = x + scale * dx
                f_trial = self.residual(trial, rest_mm, before)
                if np.linalg.norm(f_trial) < norm or scale < 1e-6:
                    break
                scale *= 0.5
            x, f, norm = trial, f_trial, np.linalg.norm(f_trial)
        else:
            if norm > 1e-6:
                x, norm = self._chord(guess, rest_mm, before)
            if norm > 1e-6:
                raise RuntimeError("tendon equilibrium does not converge (residual {:.3g})".format(norm))
        x = x.reshape(self.segments, 3)
        return x, self.tensions(x, rest_mm, before)[1]
