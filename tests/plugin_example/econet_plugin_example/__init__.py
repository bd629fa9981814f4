"""A controller defined outside econet_ros: the tests put this folder on PYTHONPATH, and the
entry point in econet_plugin_example-0.1.0.dist-info/entry_points.txt registers it as
'example-linear' (as `pip install` of a package with that entry point would)."""
import numpy as np

from econet_ros.controllers import Controller


class LinearController(Controller):
    """One logistic layer from the 13 inputs straight to the 5 muscles: 65 weights, evolvable."""

    @property
    def n_params(self) -> int:
        return (self.config.model.visual_units + 5) * 5

    def __init__(self, n_envs, config):
        super().__init__(n_envs, config)
        self.weights = np.zeros((1, self.n_params))

    def load(self, params, noise_seed=0):
        params = np.asarray(params, dtype=np.float64)
        if params.ndim != 2 or params.shape[1] != self.n_params or self.n_envs % len(params):
            raise ValueError(f"expected (k, {self.n_params}) weights, got {params.shape}")
        self.weights = params

    def act(self, obs):
        inputs = obs.network_input()                        # (n, 13)
        w = np.repeat(self.weights, self.n_envs // len(self.weights), axis=0)
        w = w.reshape(self.n_envs, 5, inputs.shape[1])
        return 1.0 / (1.0 + np.exp(-np.einsum("noi,ni->no", w, inputs)))
