"""The online problem (paper Sec. IV-V): the TorchRL env, its Gymnasium wrapper, the SAC agent; training in
`nbv.rl.train`.

Names are re-exported lazily (`common.lazy`), so importing a config module stays light.
"""

from common.lazy import lazy_exports

_EXPORTS = {
    "EnvConfig": "nbv.rl.config",
    "TrainConfig": "nbv.rl.config",
    "NBVEnv": "nbv.rl.env",
    "NBVGymEnv": "nbv.rl.gym",
    "make_actor": "nbv.rl.agent",
    "make_critic": "nbv.rl.agent",
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
