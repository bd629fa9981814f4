"""Controllers turn a batch of observations into a batch of motor outputs.

The paper's two networks and its random-movement condition are the built-in controllers; any
class with the same interface plugs in (see ``Controller``).

Networks (paper, Appendix): fully connected feed-forward layers of logistic units, no biases.
    four-layer   vision(8) -> visual hidden;  proprio(4) -> proprioceptive hidden;
                 [touch, visual hidden, proprioceptive hidden] -> intermodal hidden -> 5 outputs
    three-layer  [vision, proprio, touch] (13) -> hidden (8) -> 5 outputs
Weights per environment are one flat vector, layer after layer in the order above; within a
layer, the weight from input j to unit k sits at k * n_inputs + j (the intermodal layer's inputs
are ordered touch, visual hidden, proprioceptive hidden).
"""
from __future__ import annotations

from abc import ABC, abstractmethod

import numba
import numpy as np

from .config import Config
from .world import N_MOTOR, N_PROPRIO, Observation


class Controller(ABC):
    """A batch of n_envs controllers, one per environment.

    ``load`` gives every environment its parameters (e.g. network weights) before a batch of
    trials; ``act`` is called once per cycle and returns (n_envs, 5) outputs in [0, 1] ordered
    [eye, shoulder flexor, shoulder extensor, elbow flexor, elbow extensor].
    """

    def __init__(self, n_envs: int, config: Config):
        self.n_envs = n_envs
        self.config = config

    @property
    def n_params(self) -> int:
        """Parameters per environment that evolution searches (0: nothing to evolve)."""
        return 0

    def load(self, params: np.ndarray, noise_seed: int = 0) -> None:
        """Install (n_envs, n_params) parameters; noise_seed seeds any randomness."""

    @abstractmethod
    def act(self, obs: Observation) -> np.ndarray:
        """Motor outputs (n_envs, 5) for this cycle's observation."""


class FeedForwardNetwork(Controller):
    """Logistic feed-forward network whose layers each read one contiguous slice of an
    activation buffer laid out as [inputs, layer 1, layer 2, ...]."""

    def __init__(self, n_envs: int, config: Config, layers: list[tuple[int, int, int]]):
        """layers: (input start, input end, units) per layer; units append to the buffer."""
        super().__init__(n_envs, config)
        n_inputs = config.model.visual_units + N_PROPRIO + 1
        spans, end, n_weights = [], n_inputs, 0
        for start, stop, units in layers:
            spans.append((start, stop, end, end + units))
            n_weights += (stop - start) * units
            end += units
        self.layers = np.array(spans, dtype=np.int64)
        self.buffer_size = end
        self._n_weights = n_weights
        self.weights = np.zeros((n_envs, n_weights))

    @property
    def n_params(self) -> int:
        return self._n_weights

    def load(self, params: np.ndarray, noise_seed: int = 0) -> None:
        params = np.asarray(params, dtype=np.float64)
        if params.shape != (self.n_envs, self.n_params):
            raise ValueError(f"expected weights of shape ({self.n_envs}, {self.n_params}), "
                             f"got {params.shape}")
        self.weights = np.ascontiguousarray(params)

    def act(self, obs: Observation) -> np.ndarray:
        return self.forward(obs.network_input())

    def forward(self, inputs: np.ndarray) -> np.ndarray:
        """Outputs (n, 5) for network inputs (n, visual_units + 5)."""
        buffer = np.zeros((self.n_envs, self.buffer_size))
        buffer[:, :inputs.shape[1]] = inputs
        _forward(buffer, self.weights, self.layers)
        return buffer[:, -N_MOTOR:]


class FourLayerNetwork(FeedForwardNetwork):
    """The paper's network: intramodal visual and proprioceptive layers, then intermodal."""

    def __init__(self, n_envs: int, config: Config):
        vis, net = config.model.visual_units, config.network
        touch = vis + N_PROPRIO                      # index of the touch input
        hidden_end = touch + 1 + net.visual_hidden + net.proprio_hidden
        super().__init__(n_envs, config, [
            (0, vis, net.visual_hidden),
            (vis, touch, net.proprio_hidden),
            # touch and both intramodal layers lie side by side in the buffer
            (touch, hidden_end, net.intermodal_hidden),
            (hidden_end, hidden_end + net.intermodal_hidden, N_MOTOR),
        ])


class ThreeLayerNetwork(FeedForwardNetwork):
    """The paper's comparison network: all senses into one hidden layer."""

    def __init__(self, n_envs: int, config: Config):
        n_in = config.model.visual_units + N_PROPRIO + 1
        hidden = config.network.three_layer_hidden
        super().__init__(n_envs, config, [(0, n_in, hidden), (n_in, n_in + hidden, N_MOTOR)])


class RandomMovement(Controller):
    """The paper's chance baseline: every output drawn uniformly from [0, 1) each cycle.

    It keeps the networks' parameter count so that evolution runs unchanged (selection then
    acts on weights that do nothing)."""

    def __init__(self, n_envs: int, config: Config):
        super().__init__(n_envs, config)
        self._n_params = FourLayerNetwork(1, config).n_params
        self._rng = np.random.default_rng(0)

    @property
    def n_params(self) -> int:
        return self._n_params

    def load(self, params: np.ndarray, noise_seed: int = 0) -> None:
        self._rng = np.random.default_rng(noise_seed)

    def act(self, obs: Observation) -> np.ndarray:
        return self._rng.random((self.n_envs, N_MOTOR))


BUILTIN = {"normal": FourLayerNetwork, "three-layer": ThreeLayerNetwork,
           "random": RandomMovement}


def make_controller(condition: str, n_envs: int, config: Config) -> Controller:
    """The controller the paper uses for a condition."""
    try:
        return BUILTIN[condition](n_envs, config)
    except KeyError:
        raise ValueError(f"unknown condition '{condition}' "
                         f"(choose from {', '.join(BUILTIN)})") from None


@numba.njit(cache=True, parallel=True)
def _forward(buffer, weights, layers):
    for i in numba.prange(buffer.shape[0]):
        w = 0
        for layer in range(layers.shape[0]):
            in_start, in_stop, out_start, out_stop = layers[layer]
            for unit in range(out_start, out_stop):
                total = 0.0
                for j in range(in_start, in_stop):
                    total += weights[i, w] * buffer[i, j]
                    w += 1
                buffer[i, unit] = 1.0 / (1.0 + np.exp(-total))
