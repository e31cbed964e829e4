"""Actor and critic networks: shapes over batch shapes, bounds, SAC loss gradients."""

from __future__ import annotations

import pytest
import torch
from tensordict import TensorDict
from torch import nn

from nbv.rl.agent import CriticNet, NetworkConfig, make_actor, make_critic
from nbv.rl.builders import OptimConfig, make_loss_module


def state(batch: tuple[int, ...], tau: int = 5, side: int = 32) -> TensorDict:
    g = torch.Generator().manual_seed(0)
    pixels = torch.randint(0, 256, (*batch, tau, side, side), dtype=torch.uint8, generator=g)
    return TensorDict({"pixels": pixels,
                       "viewpoints": torch.rand(*batch, tau, 3, generator=g) * 2 - 1}, batch)


@pytest.mark.parametrize("batch", [(), (4,), (2, 3)])
def test_actor_actions_in_bounds_for_any_batch_shape(batch):
    actor = make_actor(5, 32)
    out = actor(state(batch))
    assert out["action"].shape == (*batch, 3)
    assert out["action"].abs().max() <= 1.0
    assert (out["scale"] > 0).all()


def test_critic_one_q_value_with_batchnorm3d():
    critic = make_critic(5, 32, NetworkConfig(channels=8))
    td = state((6,)).set("action", torch.zeros(6, 3))
    assert critic(td)["state_action_value"].shape == (6, 1)
    assert any(isinstance(m, nn.BatchNorm3d) for m in critic.modules())
    assert any(isinstance(m, nn.Conv3d) for m in critic.modules())


def test_critic_depends_on_action_and_frames():
    net = CriticNet(5, 32).eval()
    td = state((3,))
    a = net(td["pixels"], td["viewpoints"], torch.zeros(3, 3))
    assert not torch.allclose(a, net(td["pixels"], td["viewpoints"], torch.ones(3, 3)))
    assert not torch.allclose(a, net(255 - td["pixels"], td["viewpoints"], torch.zeros(3, 3)))


def test_sac_loss_gives_finite_gradients_to_actor_and_twin_critics():
    torch.manual_seed(0)
    actor, critic = make_actor(5, 32), make_critic(5, 32)
    loss, _ = make_loss_module(actor, critic, OptimConfig())
    td = state((8,))
    td["action"] = torch.rand(8, 3) * 2 - 1
    td["next"] = state((8,)).update({"reward": torch.randn(8, 1), "done": torch.zeros(8, 1, dtype=torch.bool),
                                     "terminated": torch.zeros(8, 1, dtype=torch.bool)})
    out = loss(td)
    assert float(out["alpha"]) == pytest.approx(0.2)
    (out["loss_actor"] + out["loss_qvalue"]).backward()
    grads = [p.grad for p in loss.qvalue_network_params.values(True, True) if p.requires_grad]
    assert grads and all(g is not None and torch.isfinite(g).all() for g in grads)
    assert loss.qvalue_network_params["module", "observation", "0", "weight"].shape[0] == 2  # twin critics


def test_actor_without_frames_reads_the_bov_vector_not_the_pixels():
    torch.manual_seed(0)
    actor = make_actor(5, 32, NetworkConfig(actor_frames=False), extra=7)
    assert not any(isinstance(m, nn.Conv2d) for m in actor.modules())
    td = state((3,)).set("bov", torch.rand(3, 7))
    loc = actor(td.clone())["loc"]
    assert torch.equal(loc, actor(td.clone().set("pixels", 255 - td["pixels"]))["loc"])
    assert not torch.allclose(loc, actor(td.clone().set("bov", torch.zeros(3, 7)))["loc"])


def test_actor_without_frames_or_bov_vector_is_refused():
    with pytest.raises(ValueError, match="needs the Bag of Views vector"):
        make_actor(5, 32, NetworkConfig(actor_frames=False))
