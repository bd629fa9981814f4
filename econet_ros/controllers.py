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

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass, field

import numba
import numpy as np

from .config import Config
from .elementary import EXP_NEAR_LIMIT, exp_near
from .world import N_MOTOR, N_PROPRIO, Observation, n_inputs, sense_rows


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
        """Install parameters, shape (n_networks, n_params): network k drives the block of
        n_envs / n_networks consecutive environments starting at k * n_envs / n_networks (so
        one row per environment, or one per econet whose trials lie side by side).
        noise_seed seeds any randomness."""

    @abstractmethod
    def act(self, obs: Observation) -> np.ndarray:
        """Motor outputs (n_envs, 5) for this cycle's observation."""

    def compiled(self, cycles: int) -> "CompiledPolicy | None":
        """The controller as arrays the engine can run whole trials with in one compiled loop
        (same results as calling ``act`` each cycle); None means the engine calls ``act``."""
        return None


@dataclass
class CompiledPolicy:
    """A network the engine evaluates itself (weights per network, ``block`` consecutive
    environments per network), or a fixed table of motor outputs (cycles, n_envs, 5)."""

    weights: np.ndarray = field(default_factory=lambda: np.zeros((1, 1)))
    block: int = 1
    layers: np.ndarray = field(default_factory=lambda: np.zeros((0, 4), dtype=np.int64))
    buffer_size: int = 0
    motor_table: np.ndarray | None = None


class FeedForwardNetwork(Controller):
    """Logistic feed-forward network whose layers each read one contiguous slice of an
    activation buffer laid out as [inputs, layer 1, layer 2, ...]."""

    def __init__(self, n_envs: int, config: Config, layers: list[tuple[int, int, int]],
                 wired: np.ndarray | None = None):
        """layers: (input start, input end, units) per layer; units append to the buffer.
        wired: the positions of the layers' flat weight vector that the parameters fill, in
        order (the others stay zero: connections a unit lacks); None: all of them."""
        super().__init__(n_envs, config)
        self.wired = wired
        spans, end, n_weights = [], n_inputs(config.model), 0
        for start, stop, units in layers:
            spans.append((start, stop, end, end + units))
            n_weights += (stop - start) * units
            end += units
        self.layers = np.array(spans, dtype=np.int64)
        self.buffer_size = end
        self._n_weights = n_weights
        self.weights = np.zeros((n_envs, n_weights))
        self.block = 1

    @property
    def n_params(self) -> int:
        return self._n_weights if self.wired is None else len(self.wired)

    def weights_reading(self, sense: str) -> np.ndarray:
        """Bool mask over the flat weight vector: True for every weight that reads one of the
        sense's input units ("vision", "proprio" or "touch"), wherever the layers put it (a
        lesion severs a sense with it)."""
        senses = sense_rows(self.config.model.visual_units)
        if sense not in senses:
            raise ValueError(f"unknown sense '{sense}' (choose from {', '.join(senses)})")
        first, stop = senses[sense]
        mask = []
        for start, end, out_start, out_stop in self.layers:   # unit by unit, as forward_block
            reads = np.arange(start, end)                     # the buffer rows a unit reads
            mask.append(np.tile((reads >= first) & (reads < stop), out_stop - out_start))
        mask = np.concatenate(mask)
        return mask if self.wired is None else mask[self.wired]

    def load(self, params: np.ndarray, noise_seed: int = 0) -> None:
        params = np.asarray(params, dtype=np.float64)
        if params.ndim != 2 or params.shape[1] != self.n_params or not params.shape[0] or \
                self.n_envs % params.shape[0]:
            raise ValueError(f"expected weights of shape (k, {self.n_params}) with k dividing "
                             f"{self.n_envs} environments, got {params.shape}")
        if self.wired is not None:
            full = np.zeros((params.shape[0], self._n_weights))
            full[:, self.wired] = params
            params = full
        self.weights = np.ascontiguousarray(params)
        self.block = self.n_envs // params.shape[0]

    def act(self, obs: Observation) -> np.ndarray:
        return self._outputs(obs.vision, obs.proprio, obs.touch)

    def forward(self, inputs: np.ndarray) -> np.ndarray:
        """Outputs (n, 5) for network inputs (n, n_inputs)."""
        inputs = np.asarray(inputs, dtype=np.float64)
        units = self.config.model.visual_units
        if inputs.ndim != 2:
            raise ValueError(f"network inputs must have shape ({self.n_envs}, {units + 5}), "
                             f"got {inputs.shape}")
        return self._outputs(inputs[:, :units], inputs[:, units:-1], inputs[:, -1])

    def _outputs(self, vision: np.ndarray, proprio: np.ndarray, touch: np.ndarray) -> np.ndarray:
        """Outputs for the inputs by sense, read in place (no concatenated copy)."""
        vision, proprio, touch = (np.asarray(a, dtype=np.float64) for a in (vision, proprio, touch))
        n, units = self.n_envs, self.config.model.visual_units
        if vision.shape != (n, units) or proprio.shape != (n, N_PROPRIO) or touch.shape != (n,):
            raise ValueError(f"network inputs for {n} environments must be vision ({n}, {units}), "
                             f"proprioception ({n}, {N_PROPRIO}) and touch ({n},); got "
                             f"{vision.shape}, {proprio.shape}, {touch.shape}")
        out = np.empty((n, N_MOTOR))
        _forward_batch(vision, proprio, touch, self.weights, self.block, self.layers,
                       self.buffer_size, out)
        return out

    def compiled(self, cycles: int) -> CompiledPolicy:
        return CompiledPolicy(self.weights, self.block, self.layers, self.buffer_size)


class FourLayerNetwork(FeedForwardNetwork):
    """The paper's network: intramodal visual and proprioceptive layers, then intermodal.
    Scrambled (network.first_layer_wiring), the first two layers read all vision and
    proprioception inputs, but each unit has weights only from a random subset of them of the
    size it reads when modular (scrambled_wiring): the same units and weight count, the senses
    mixed."""

    def __init__(self, n_envs: int, config: Config):
        net, rows = config.network, sense_rows(config.model.visual_units)
        vis, touch = rows["vision"][1], rows["touch"][0]
        hidden_end = touch + 1 + net.visual_hidden + net.proprio_hidden
        scrambled = net.first_layer_wiring == "scrambled"
        super().__init__(n_envs, config, [
            (0, touch if scrambled else vis, net.visual_hidden),
            (0 if scrambled else vis, touch, net.proprio_hidden),
            # touch and both intramodal layers lie side by side in the buffer
            (touch, hidden_end, net.intermodal_hidden),
            (hidden_end, hidden_end + net.intermodal_hidden, N_MOTOR),
        ], scrambled_wiring(config) if scrambled else None)


def scrambled_wiring(config: Config) -> np.ndarray:
    """The weight positions a scrambled four-layer net fills in its layers' flat vector: each
    visual hidden unit reads visual_units, each proprioceptive one N_PROPRIO of the vision and
    proprioception inputs, a subset drawn without repeats per unit from network.wiring_seed
    and read in input order; every later weight as in the modular net."""
    net, rows = config.network, sense_rows(config.model.visual_units)
    vis, senses = rows["vision"][1], rows["proprio"][1]     # senses: vision and proprioception
    rng = np.random.default_rng(net.wiring_seed)
    sizes = [vis] * net.visual_hidden + [N_PROPRIO] * net.proprio_hidden
    first = [unit * senses + np.sort(rng.choice(senses, size, replace=False))
             for unit, size in enumerate(sizes)]
    start = senses * len(sizes)
    later = (1 + net.visual_hidden + net.proprio_hidden + N_MOTOR) * net.intermodal_hidden
    return np.concatenate([*first, np.arange(start, start + later)])


class ThreeLayerNetwork(FeedForwardNetwork):
    """The paper's comparison network: all senses into one hidden layer."""

    def __init__(self, n_envs: int, config: Config):
        n_in = n_inputs(config.model)
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

    def compiled(self, cycles: int) -> CompiledPolicy:
        # One draw for all cycles consumes the generator exactly as ``cycles`` calls of act.
        return CompiledPolicy(motor_table=self._rng.random((cycles, self.n_envs, N_MOTOR)))


# --- the logistic, vectorised -------------------------------------------------------------------

@numba.njit(cache=True, inline="always")
def logistic(total, out):
    """out = 1 / (1 + exp(-total)), elementwise; vectorised, with math.exp only for the rare
    |total| >= EXP_NEAR_LIMIT (or NaN)."""
    far = False
    for env in range(total.shape[0]):
        out[env] = 1.0 / (1.0 + exp_near(-total[env]))
        far |= not abs(total[env]) < EXP_NEAR_LIMIT
    if far:
        for env in range(total.shape[0]):
            if not abs(total[env]) < EXP_NEAR_LIMIT:
                out[env] = 1.0 / (1.0 + math.exp(-total[env]))


@numba.njit(cache=True, inline="always")
def forward_block(buffer, weights, layers, total):
    """One network driving a block of environments: buffer is (activations, envs), and each
    layer fills its rows from its input rows. The loops over environments vectorise; ``total``
    is scratch of one row."""
    w = 0
    for layer in range(layers.shape[0]):
        in_start, in_stop, out_start, out_stop = layers[layer]
        for unit in range(out_start, out_stop):
            total[:] = 0.0
            for j in range(in_start, in_stop):
                weight = weights[w]
                for env in range(total.shape[0]):
                    total[env] += weight * buffer[j, env]
                w += 1
            logistic(total, buffer[unit])


@numba.njit(cache=True, parallel=True)
def _forward_batch(vision, proprio, touch, weights, block, layers, buffer_size, out):
    """Outputs ``out`` (n_envs, 5) for inputs [vision, proprioception, touch] per environment;
    network k drives environments [k*block, (k+1)*block). Activations are (units, envs of the
    block), as in forward_block; all scratch is allocated once, outside the parallel loop."""
    n_blocks, n_vision = weights.shape[0], vision.shape[1]
    buffer = np.empty((n_blocks, buffer_size, block))
    total = np.empty((n_blocks, block))
    for k in numba.prange(n_blocks):
        for m in range(block):
            i = k * block + m
            for j in range(n_vision):
                buffer[k, j, m] = vision[i, j]
            for j in range(N_PROPRIO):
                buffer[k, n_vision + j, m] = proprio[i, j]
            buffer[k, n_vision + N_PROPRIO, m] = touch[i]
        forward_block(buffer[k], weights[k], layers, total[k])
        for m in range(block):
            for u in range(N_MOTOR):
                out[k * block + m, u] = buffer[k, buffer_size - N_MOTOR + u, m]


def transplant(small: FeedForwardNetwork, large: FeedForwardNetwork,
               weights: np.ndarray) -> np.ndarray:
    """The weights of ``small`` laid out for ``large``, a network of the same layers, each at
    least as wide: every unit of small becomes the unit of the same rank in its layer of large,
    keeps the weights from the inputs it had, and every weight small does not have is exactly
    zero, so that large computes exactly what small does (an added unit's output, 0.5, reaches
    nothing). Works on a flat vector or a batch (k, small.n_params)."""
    if small.layers.shape != large.layers.shape or small.layers[0, 0] != large.layers[0, 0]:
        raise ValueError("transplant needs two networks of the same layers and inputs")
    if (np.diff(small.layers[:, 2:]) > np.diff(large.layers[:, 2:])).any():
        raise ValueError("every layer of the large network must be at least as wide")
    where = np.arange(small.buffer_size)      # small's buffer rows in large's (inputs stay)
    for (_, _, s_out, s_stop), (_, _, l_out, _) in zip(small.layers, large.layers):
        where[s_out:s_stop] = np.arange(s_stop - s_out) + l_out
    weights = np.asarray(weights, dtype=np.float64)
    moved = np.zeros((*weights.shape[:-1], large.n_params))
    source, target = _layer_offsets(small), _layer_offsets(large)
    for layer, (s_in, s_stop, s_out, s_end) in enumerate(small.layers):
        l_in, l_stop = large.layers[layer, :2]
        reads = where[s_in:s_stop]
        if (reads < l_in).any() or (reads >= l_stop).any():
            raise ValueError(f"layer {layer} of the large network does not read the same inputs")
        for unit in range(s_end - s_out):
            first = source[layer] + unit * (s_stop - s_in)
            start = target[layer] + unit * (l_stop - l_in)
            moved[..., start + reads - l_in] = weights[..., first:first + s_stop - s_in]
    return moved


def _layer_offsets(network: FeedForwardNetwork) -> np.ndarray:
    """Where each layer's weights start in the flat vector."""
    counts = (network.layers[:, 1] - network.layers[:, 0]) * (network.layers[:, 3]
                                                              - network.layers[:, 2])
    return np.concatenate([[0], np.cumsum(counts)[:-1]])
