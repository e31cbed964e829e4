"""The SAC actor and critic networks of paper Sec. V-A.

Both read the env's state: `pixels` (..., tau, S, S) uint8 grayscale frames and
`viewpoints` (..., tau, 3) normalised locations. Leading batch dimensions are
flattened inside and restored on output, so the same modules serve one env,
a `ParallelEnv` batch and replay-buffer samples.

Actor (the paper's Fig. 5): an observation sub-network (2D convolutions with
the tau frames as channels) and a location sub-network (fully connected),
fused and mapped to the mean and scale of a TanhNormal over [-1, 1]^3.

Critic: the frame stack through 3D convolutions (time as depth) each followed
by BatchNorm3d and ReLU, flattened, then two fully connected layers of 128;
the locations and the action through fully connected layers of 64 and 128;
the two fused through fully connected layers of 128 and then ONE output.
The paper's critic ends in 3 outputs ("the output quality value vector");
SAC's soft Q-function is a scalar per state-action pair, so ours ends in 1.

With `extra` > 0 (`EnvConfig.bov_observation`, beyond the paper) both also read the state's `bov`
vector (..., extra), concatenated to the flattened convolution output before its first fully connected
layer. With `extra` = 0 the networks, their parameters and their initial draws are the paper's.
With `NetworkConfig.actor_frames` off (beyond the paper) the actor has no convolutions: its observation
sub-network is the fully connected layer over the `bov` vector alone (it still takes `pixels`, unread).
"""

from __future__ import annotations

import torch
from tensordict.nn import TensorDictModule
from torch import nn
from torchrl.data import Bounded
from torchrl.modules import NormalParamExtractor, ProbabilisticActor, TanhNormal, ValueOperator

from nbv.rl.config import NetworkConfig


def _flatten_batch(x: torch.Tensor, event_dims: int) -> tuple[torch.Tensor, torch.Size]:
    batch = x.shape[: x.dim() - event_dims]
    return x.reshape(-1, *x.shape[x.dim() - event_dims:]), batch


def _conv_out_features(net: nn.Module, shape: tuple[int, ...]) -> int:
    with torch.no_grad():
        training = net.training
        out = net.eval()(torch.zeros(1, *shape)).shape[1:].numel()
        net.train(training)
    return out


class ActorNet(nn.Module):
    """Observation and location sub-networks fused into (loc, scale) of the action distribution.

    Shape:
        - pixels: (*, tau, S, S) uint8 or float in [0, 255]
        - viewpoints: (*, tau, 3)
        - output: loc (*, 3), scale (*, 3)
    """

    def __init__(self, history: int, obs_size: int, config: NetworkConfig = NetworkConfig(),
                 extra: int = 0) -> None:
        super().__init__()
        c, h = config.channels, config.hidden
        if not config.actor_frames and extra == 0:
            raise ValueError("an actor without frames needs the Bag of Views vector (extra > 0)")
        self.observation = nn.Sequential(
            nn.Conv2d(history, c, 5, stride=2, padding=2), nn.ReLU(),
            nn.Conv2d(c, c, 3, stride=2, padding=1), nn.ReLU(),
            nn.Conv2d(c, c, 3, stride=2, padding=1), nn.ReLU(),
            nn.Flatten(),
        ) if config.actor_frames else None
        conv_out = 0 if self.observation is None else _conv_out_features(
            self.observation, (history, obs_size, obs_size))
        self.observation_fc = nn.Sequential(nn.Linear(conv_out + extra, h), nn.ReLU())
        self.location = nn.Sequential(
            nn.Linear(3 * history, config.location_hidden), nn.ReLU(),
            nn.Linear(config.location_hidden, h), nn.ReLU())
        self.head = nn.Sequential(nn.Linear(2 * h, h), nn.ReLU(), nn.Linear(h, 6), NormalParamExtractor())

    def features(self, pixels: torch.Tensor, viewpoints: torch.Tensor,
                 bov: torch.Tensor | None = None) -> tuple[torch.Tensor, torch.Size]:
        """The fused observation and location features (B, 2 x hidden), B the flattened leading dimensions
        (returned): what the head reads."""
        locations, batch = _flatten_batch(viewpoints, 2)
        if self.observation is None:
            observed = _flatten_batch(bov, 1)[0]
        else:
            observed = _with_extra(self.observation(_flatten_batch(pixels.float() / 255.0, 3)[0]), bov)
        return torch.cat([self.observation_fc(observed), self.location(locations.flatten(1))], dim=-1), batch

    def forward(self, pixels: torch.Tensor, viewpoints: torch.Tensor,
                bov: torch.Tensor | None = None) -> tuple[torch.Tensor, torch.Tensor]:
        features, batch = self.features(pixels, viewpoints, bov)
        loc, scale = self.head(features)
        return loc.reshape(*batch, 3), scale.reshape(*batch, 3)


class CriticNet(nn.Module):
    """One soft Q-value of (state, action): 3D convolutions over the frame stack, FC over locations.

    Shape:
        - pixels: (*, tau, S, S); viewpoints: (*, tau, 3); action: (*, 3)
        - output: (*, 1)
    """

    def __init__(self, history: int, obs_size: int, config: NetworkConfig = NetworkConfig(),
                 extra: int = 0) -> None:
        super().__init__()
        c, h = config.channels // 2, config.hidden
        depth_kernel = min(3, history)
        self.observation = nn.Sequential(
            nn.Conv3d(1, c, (depth_kernel, 5, 5), stride=(1, 2, 2), padding=(0, 2, 2)),
            nn.BatchNorm3d(c), nn.ReLU(),
            nn.Conv3d(c, c, (1, 3, 3), stride=(1, 2, 2), padding=(0, 1, 1)),
            nn.BatchNorm3d(c), nn.ReLU(),
            nn.Conv3d(c, c, (1, 3, 3), stride=(1, 2, 2), padding=(0, 1, 1)),
            nn.BatchNorm3d(c), nn.ReLU(),
            nn.Flatten(),
        )
        conv_out = _conv_out_features(self.observation, (1, history, obs_size, obs_size))
        self.observation_fc = nn.Sequential(nn.Linear(conv_out + extra, h), nn.ReLU(), nn.Linear(h, h),
                                            nn.ReLU())
        self.location = nn.Sequential(
            nn.Linear(3 * history + 3, config.location_hidden), nn.ReLU(),
            nn.Linear(config.location_hidden, h), nn.ReLU())
        self.head = nn.Sequential(nn.Linear(2 * h, h), nn.ReLU(), nn.Linear(h, 1))

    def forward(self, pixels: torch.Tensor, viewpoints: torch.Tensor, action: torch.Tensor,
                bov: torch.Tensor | None = None) -> torch.Tensor:
        frames, batch = _flatten_batch(pixels.float() / 255.0, 3)
        locations, _ = _flatten_batch(viewpoints, 2)
        actions, _ = _flatten_batch(action, 1)
        encoded = self.observation_fc(_with_extra(self.observation(frames.unsqueeze(1)), bov))
        located = self.location(torch.cat([locations.flatten(1), actions], dim=-1))
        return self.head(torch.cat([encoded, located], dim=-1)).reshape(*batch, 1)


def _with_extra(encoded: torch.Tensor, extra: torch.Tensor | None) -> torch.Tensor:
    """The flattened convolution output, with the `bov` vector (flattened like it) after it if given."""
    return encoded if extra is None else torch.cat([encoded, _flatten_batch(extra, 1)[0]], dim=-1)


def _keys(extra: int) -> list[str]:
    return ["pixels", "viewpoints"] + (["bov"] if extra else [])


def make_actor(history: int, obs_size: int, config: NetworkConfig = NetworkConfig(),
               extra: int = 0) -> ProbabilisticActor:
    """The stochastic policy: `pixels`, `viewpoints` (and `bov` when `extra` > 0) -> `action` in [-1, 1]^3
    (TanhNormal)."""
    net = TensorDictModule(ActorNet(history, obs_size, config, extra), in_keys=_keys(extra),
                           out_keys=["loc", "scale"])
    return ProbabilisticActor(
        net, in_keys=["loc", "scale"], spec=Bounded(-1.0, 1.0, shape=(3,)),
        distribution_class=TanhNormal, distribution_kwargs={"low": -1.0, "high": 1.0},
        return_log_prob=False, default_interaction_type="random")


def make_critic(history: int, obs_size: int, config: NetworkConfig = NetworkConfig(),
                extra: int = 0) -> ValueOperator:
    """One Q network: `pixels`, `viewpoints`, `action` (and `bov` when `extra` > 0) -> `state_action_value`;
    SACLoss makes the twin."""
    return ValueOperator(CriticNet(history, obs_size, config, extra),
                         in_keys=["pixels", "viewpoints", "action"] + (["bov"] if extra else []))
