"""scikit-learn's GaussianProcessRegressor on a dataset given as JSON.

Reads {"x": [[...]], "y": [[...]], "queries": [[...]], "length_scales": [...],
"signal_variance": s, "noise_variance": n} on stdin and writes the posterior
mean at the queries, the log marginal likelihood and its gradient with
respect to the log-hyperparameters, at exactly those hyperparameters.
"""
import json
import sys

import numpy as np
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import RBF, ConstantKernel, WhiteKernel

request = json.load(sys.stdin)
x = np.asarray(request["x"], dtype=float)
y = np.asarray(request["y"], dtype=float)
queries = np.asarray(request["queries"], dtype=float)

kernel = ConstantKernel(request["signal_variance"], constant_value_bounds="fixed") * RBF(
    np.asarray(request["length_scales"], dtype=float), length_scale_bounds="fixed"
) + WhiteKernel(request["noise_variance"], noise_level_bounds="fixed")
gp = GaussianProcessRegressor(kernel=kernel, alpha=0.0, optimizer=None, normalize_y=False)
gp.fit(x, y)

# Gradient with free bounds: theta order is [log c, log l_1..l_D, log noise].
free = ConstantKernel(request["signal_variance"]) * RBF(
    np.asarray(request["length_scales"], dtype=float)
) + WhiteKernel(request["noise_variance"])
gp_free = GaussianProcessRegressor(kernel=free, alpha=0.0, optimizer=None, normalize_y=False)
gp_free.fit(x, y)
lml, gradient = gp_free.log_marginal_likelihood(gp_free.kernel_.theta, eval_gradient=True)

json.dump(
    {
        "mean": gp.predict(queries).reshape(len(queries), -1).tolist(),
        "log_marginal_likelihood": float(gp.log_marginal_likelihood_value_),
        "log_marginal_likelihood_free": float(lml),
        "gradient": gradient.tolist(),
    },
    sys.stdout,
)
