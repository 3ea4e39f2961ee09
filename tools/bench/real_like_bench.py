#!/usr/bin/env python3
"""What makes the real robot's recordings hard, measured on the independent robot's real-like files.

    real_like_bench.py babbling FILE.csv [--report ROBOT.json] [--train-rows 1500] [--cdcr CDCR] [--kernels] [--json]
    real_like_bench.py repeatability FILE.csv [--report ROBOT.json] [--json]

babbling: the rows in order, the first 80 % to train and the last 20 % to
test (as the lab's), then
  - the share of rows whose constant-curvature bend exceeds pi/2, and the
    spread (max - min) of the pair sums l1 + l3 and l2 + l4;
  - the nominal model's mean position error on the test rows;
  - scikit-learn's GP (constant x ARD squared exponential + white noise,
    normalised outputs, 2 restarts) from the cables to the tip position,
    given all cables, and given only the two differences l3 - l1, l2 - l4;
    at most --train-rows training rows, evenly spaced;
  - with --kernels: how far other exact GPs on the same rows get, all four
    cables given: Matern kernels (nu 1.5 and 2.5, ARD) in place of the
    squared exponential, and each also given the sign of each cable's last
    move (-1, 0, +1, from the rows in order);
  - the noise floor of the robot's report (--report: independent_robot.py's
    JSON, the first session's), when given;
  - with --cdcr (the cdcr executable): the project's model, `cdcr train` on
    the rows scikit-learn's GP got (as independent samples: no t_s) and on
    the whole first 80 % as the sequence it is, each `cdcr eval`uated on the
    last 20 %: the compensated mean position error and the encoding chosen.
repeatability: the same split, and
  - the same command from the same previous one: the mean over pairs of
    such visits of |p_a - p_b| / sqrt(2), from the file alone (commands told
    apart by their cable values);
  - a joints-only GP (the cables) against one also given the sign of each
    cable's last move (-1, 0, +1);
  - with --cdcr: the project's model, `cdcr train` on the first 80 % as the
    sequence it is, with and without `--no-history`, each `cdcr eval`uated
    on the last 20 %: the compensated mean position error, whether the
    history inputs were kept, r95's coverage, the rows flagged as
    extrapolating and those outside the fitted rows' range (which flag only
    in images before 2.6), and the same test rows from power-up (the first
    rows with the cables' state unknown; any sequence model with hysteresis).
One segment of four cables (l1_1..l1_4) only. Needs numpy and scikit-learn.
"""

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import independent_robot as robot  # noqa: E402

TRAIN_SHARE = 0.8


def write_rows(path, source, rows, with_time):
    """The source CSV's comment lines, header and the given data rows (0-based), optionally without t_s."""
    with open(source) as f:
        lines = f.read().splitlines()
    comments = [line for line in lines if line.startswith("#")]
    table = [line for line in lines if not line.startswith("#")]
    header, data = table[0], table[1:]
    drop = not with_time and header.startswith("t_s,")

    def cut(line):
        return line.split(",", 1)[1] if drop else line

    with open(path, "w") as f:
        f.write("\n".join([line for line in comments if not (drop and "t_s" in line)] + [cut(header)] +
                          [cut(data[i]) for i in rows]) + "\n")


def cdcr_json(cdcr, *arguments):
    done = subprocess.run([cdcr, *arguments, "--json"], capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit("real_like_bench.py: error: cdcr {} failed: {}".format(arguments[0], done.stderr.strip()))
    return json.loads(done.stdout)


def cdcr_model(cdcr, source, train_rows, test_rows, with_time, length_mm, radius_mm, options=()):
    """cdcr train on train_rows, cdcr eval on test_rows: the compensated error, the encoding, the cable fit's counts,
    r95's coverage, the flags; with a hysteresis model, also the test rows evaluated from power-up."""
    with tempfile.TemporaryDirectory() as work:
        train, test, image = (os.path.join(work, name) for name in ("train.csv", "test.csv", "model.img"))
        write_rows(train, source, train_rows, with_time)
        write_rows(test, source, test_rows, with_time)
        trained = cdcr_json(cdcr, "train", "--data", train, "--out", image, "--holdout", "0", "--segments", "1",
                            "--length", str(length_mm), "--radius", str(radius_mm), *options)
        evaluated = cdcr_json(cdcr, "eval", "--model", image, "--data", test)
        # The test rows as a session the board starts at power-up, the cables' state unknown.
        used_hysteresis = with_time and (trained.get("hysteresis") or {}).get("used")
        power_up = cdcr_json(cdcr, "eval", "--model", image, "--data", test, "--from-power-up") \
            if used_hysteresis else None
    out = {"compensated_mm": evaluated["compensated"]["position_mm"], "encoding": trained["encoding"],
           "model": trained["model"]["reason"], "cable_inputs": trained["cable_inputs"],
           "extrapolating": evaluated["extrapolating"], "outside_range": evaluated["outside_range"],
           "uncertainty": trained.get("uncertainty")}
    if with_time and trained.get("hysteresis"):
        out["history"] = trained["hysteresis"].get("history", {}).get("reason")
    if evaluated.get("coverage"):
        out["r95_coverage"] = evaluated["coverage"]
    if power_up:
        out["from_power_up"] = {"extrapolating": power_up["extrapolating"], "power_up": power_up["power_up"]}
    return out


def read(path):
    """The header's geometry and the table: cables (n x 4) and positions (n x 3)."""
    length_mm = radius_mm = None
    with open(path) as f:
        lines = f.read().splitlines()
    for line in lines:
        if line.startswith("# nominal geometry:"):
            parts = line.replace(",", " ").split()
            length_mm = float(parts[parts.index("L") + 2])
            radius_mm = float(parts[parts.index("r") + 2])
    rows = [line for line in lines if not line.startswith("#")]
    header = rows[0].split(",")
    table = np.array([r.split(",") for r in rows[1:]], dtype=float)
    cables = [header.index("l1_{}".format(j)) for j in range(1, 5)]
    if "l2_1" in header or "l1_5" in header:
        sys.exit("real_like_bench.py: error: one segment of four cables only")
    position = [header.index(name) for name in ("x", "y", "z")]
    return length_mm, radius_mm, table[:, cables], table[:, position]


def fit_gp(x_train, y_train, x_test, seed=0, matern_nu=None):
    """scikit-learn's GP, ARD squared exponential (or Matern of matern_nu) + white noise, on standardised
    inputs; the test predictions."""
    from sklearn.gaussian_process import GaussianProcessRegressor
    from sklearn.gaussian_process.kernels import RBF, ConstantKernel, Matern, WhiteKernel
    mean, scale = x_train.mean(axis=0), x_train.std(axis=0)
    scale[scale == 0.0] = 1.0
    ones = np.ones(x_train.shape[1])
    shape = RBF(ones, (1e-2, 1e3)) if matern_nu is None else Matern(ones, (1e-2, 1e3), nu=matern_nu)
    kernel = ConstantKernel(1.0, (1e-3, 1e3)) * shape + WhiteKernel(1e-2, (1e-6, 1.0))
    gp = GaussianProcessRegressor(kernel, normalize_y=True, n_restarts_optimizer=2, random_state=seed)
    gp.fit((x_train - mean) / scale, y_train)
    return gp.predict((x_test - mean) / scale), gp.kernel_


def mean_distance(a, b):
    return float(np.mean(np.linalg.norm(a - b, axis=1)))


def split(n):
    return int(round(TRAIN_SHARE * n))


def babbling(path, train_rows, cdcr=None, kernels=False):
    length_mm, radius_mm, cables, position = read(path)
    n = len(cables)
    cut = split(n)
    pick = np.unique(np.linspace(0, cut - 1, min(cut, train_rows)).round().astype(int))
    nominal = np.array([robot.nominal_pose_general(c, 1, 4, length_mm, radius_mm)[:3, 3] for c in cables[cut:]])
    thetas = np.array([robot.joints_from_cables_general(c, radius_mm)[1] for c in cables])
    differences = np.stack([cables[:, 2] - cables[:, 0], cables[:, 1] - cables[:, 3]], axis=1)
    out = {"rows": n, "train_rows_used": int(len(pick)), "test_rows": n - cut,
           "beyond_quarter_turn": float(np.mean(thetas > 0.5 * math.pi)),
           "pair_sum_spread_mm": [float(np.ptp(cables[:, 0] + cables[:, 2])),
                                  float(np.ptp(cables[:, 1] + cables[:, 3]))],
           "nominal_mm": mean_distance(nominal, position[cut:])}
    for name, inputs in (("gp_all_cables_mm", cables), ("gp_differences_mm", differences)):
        predicted, kernel = fit_gp(inputs[pick], position[pick], inputs[cut:])
        out[name] = mean_distance(predicted, position[cut:])
        out[name.replace("_mm", "_kernel")] = str(kernel)
    if kernels:
        moves = np.sign(np.diff(cables, axis=0, prepend=cables[:1]))
        with_sign = np.hstack([cables, moves])
        for name, inputs, nu in (("gp_matern15_mm", cables, 1.5), ("gp_matern25_mm", cables, 2.5),
                                 ("gp_sign_mm", with_sign, None), ("gp_sign_matern15_mm", with_sign, 1.5)):
            predicted, _ = fit_gp(inputs[pick], position[pick], inputs[cut:], matern_nu=nu)
            out[name] = mean_distance(predicted, position[cut:])
    if cdcr:
        test = list(range(cut, n))
        out["cdcr_same_rows"] = cdcr_model(cdcr, path, pick, test, False, length_mm, radius_mm)
        out["cdcr_sequence"] = cdcr_model(cdcr, path, range(cut), test, True, length_mm, radius_mm)
    return out


def command_ids(cables):
    """Rows with the same cable values (to 1e-4 mm) get the same id."""
    ids, out = {}, []
    for row in cables:
        out.append(ids.setdefault(tuple(np.round(row, 4)), len(ids)))
    return np.array(out)


def repeatability(path, cdcr=None):
    length_mm, radius_mm, cables, position = read(path)
    n = len(cables)
    cut = split(n)
    ids = command_ids(cables)
    groups = {}
    for i in range(1, n):
        groups.setdefault((ids[i - 1], ids[i]), []).append(position[i])
    distances = [np.linalg.norm(p[a] - p[b]) / math.sqrt(2.0) for p in groups.values()
                 for a in range(len(p)) for b in range(a + 1, len(p))]
    # The sign of each cable's last move; the first row is reached from home, the straight lengths L.
    before = np.vstack([np.full((1, cables.shape[1]), length_mm), cables[:-1]])
    moves = cables - before
    signs = np.zeros_like(cables)
    last = np.zeros(cables.shape[1])
    for i in range(n):
        moved = np.abs(moves[i]) > 1e-6
        last[moved] = np.sign(moves[i][moved])
        signs[i] = last
    out = {"rows": n, "commands": int(ids.max() + 1), "test_rows": n - cut,
           "same_transition_mm": float(np.mean(distances)),
           "transitions_repeated": int(sum(1 for p in groups.values() if len(p) > 1))}
    for name, inputs in (("gp_joints_only_mm", cables), ("gp_sign_of_last_move_mm", np.hstack([cables, signs]))):
        predicted, kernel = fit_gp(inputs[:cut], position[:cut], inputs[cut:])
        out[name] = mean_distance(predicted, position[cut:])
        out[name.replace("_mm", "_kernel")] = str(kernel)
    if cdcr:
        test = list(range(cut, n))
        out["cdcr_sequence"] = cdcr_model(cdcr, path, range(cut), test, True, length_mm, radius_mm)
        out["cdcr_sequence_no_history"] = cdcr_model(cdcr, path, range(cut), test, True, length_mm, radius_mm,
                                                     ("--no-history",))
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("collection", choices=("babbling", "repeatability"))
    parser.add_argument("file", help="a session CSV of independent_robot.py")
    parser.add_argument("--report", help="independent_robot.py's --report JSON: adds the first session's floor")
    parser.add_argument("--train-rows", type=int, default=1500, help="babbling: training rows used (default 1500)")
    parser.add_argument("--cdcr", help="the cdcr executable, to measure the project's model too")
    parser.add_argument("--kernels", action="store_true",
                        help="babbling: also Matern kernels and the sign of each cable's last move")
    parser.add_argument("--json", action="store_true", help="print the figures as one JSON object")
    args = parser.parse_args(argv)
    out = (babbling(args.file, args.train_rows, args.cdcr, args.kernels) if args.collection == "babbling"
           else repeatability(args.file, args.cdcr))
    if args.report:
        with open(args.report) as f:
            out["noise_floor_mm"] = json.load(f)["sessions"][0]["noise_floor"]["position_mm"]
    if args.json:
        print(json.dumps(out))
    else:
        for key, value in out.items():
            print("{:28s} {}".format(key, value))
    return 0


if __name__ == "__main__":
    sys.exit(main())
