"""scikit-learn's GaussianProcessRegressor fitting the data that
cdcr-bench-training exported: the same normalised inputs and outputs, the
same kernel form (constant * ARD RBF + white noise), the same bounds and the
same number of optimiser starts. Prints one JSON object like the C++ side,
with the likelihood evaluations that scikit-learn's L-BFGS-B (scipy's, the
default optimiser's settings) made.
"""
import argparse
import json
import statistics
import time
import warnings

import numpy as np
import scipy.optimize
import threadpoolctl
from sklearn.exceptions import ConvergenceWarning
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import RBF, ConstantKernel, WhiteKernel

parser = argparse.ArgumentParser()
parser.add_argument("xy")
parser.add_argument("--restarts", type=int, default=0)
parser.add_argument("--repetitions", type=int, default=3)
args = parser.parse_args()

with open(args.xy) as f:
    data = json.load(f)
x = np.asarray(data["x"])
y = np.asarray(data["y"])
bounds = data["bounds"]

warnings.simplefilter("ignore", ConvergenceWarning)
evaluations = 0


def counting_optimizer(objective, initial_theta, bounds):
    """scikit-learn's default optimiser (L-BFGS-B through scipy.optimize.minimize
    with the gradient), counting the likelihood evaluations."""
    global evaluations
    result = scipy.optimize.minimize(objective, initial_theta, method="L-BFGS-B", jac=True, bounds=bounds)
    evaluations += result.nfev
    return result.x, result.fun


seconds = []
evaluations_per_run = []
for repetition in range(args.repetitions):
    kernel = ConstantKernel(1.0, constant_value_bounds=tuple(bounds["signal_variance"])) * RBF(
        np.ones(x.shape[1]), length_scale_bounds=tuple(bounds["length_scale"])
    ) + WhiteKernel(0.1, noise_level_bounds=tuple(bounds["noise_variance"]))
    gp = GaussianProcessRegressor(kernel=kernel, alpha=0.0, optimizer=counting_optimizer,
                                  n_restarts_optimizer=args.restarts, random_state=repetition)
    evaluations = 0
    start = time.perf_counter()
    gp.fit(x, y)
    seconds.append(time.perf_counter() - start)
    evaluations_per_run.append(evaluations)

# The BLAS/LAPACK numpy and scipy run on (Debian's alternatives pick it:
# OpenBLAS once libopenblas0 is installed, else the reference BLAS, which
# threadpoolctl does not list).
blas = [f"{p['internal_api']} {p['version']} ({p['num_threads']} threads)" for p in threadpoolctl.threadpool_info()
        if p["user_api"] == "blas"]

print(
    json.dumps(
        {
            "samples": int(x.shape[0]),
            "inputs": int(x.shape[1]),
            "outputs": int(y.shape[1]),
            "starts": args.restarts + 1,
            "median_seconds": statistics.median(seconds),
            "seconds": seconds,
            "log_marginal_likelihood": float(gp.log_marginal_likelihood_value_),
            "likelihood_evaluations": evaluations_per_run[-1],
            "kernel": str(gp.kernel_),
            "blas": ", ".join(blas) or "reference BLAS (single-threaded)",
        }
    )
)
