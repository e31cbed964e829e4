"""Spherical k-means with k-means++ seeding and warm start (the BoV's codebook update, paper Sec. III step 3).

The Bag of Views compares descriptors and words by cosine (paper Eq. 1-2), so
its words are clustered on the unit sphere: a point joins the centre of highest
cosine, a centre is the normalised mean of its points. On unit vectors this is
Lloyd's k-means with squared Euclidean distance 2 - 2 cos, and k-means++ seeds
with probability proportional to that distance. Warm start: the previous words
are the first centres, k-means++ adds the rest, so a codebook that grows from K
to K' words keeps what it had learned.
"""

from __future__ import annotations

import torch
import torch.nn.functional as F


def _check(x: torch.Tensor, k: int, init: torch.Tensor | None) -> None:
    if x.ndim != 2 or x.shape[0] < 1:
        raise ValueError(f"x must be (n, D) with n >= 1, got {tuple(x.shape)}")
    if not 1 <= k <= x.shape[0]:
        raise ValueError(f"k must lie in [1, n={x.shape[0]}], got {k}")
    if init is not None and (init.ndim != 2 or init.shape[1] != x.shape[1] or init.shape[0] > k):
        raise ValueError(f"init must be (k0 <= {k}, {x.shape[1]}), got {tuple(init.shape)}")


def kmeans_plusplus(x: torch.Tensor, k: int, init: torch.Tensor | None = None,
                    generator: torch.Generator | None = None) -> torch.Tensor:
    """Seed `k` centres on the unit sphere by k-means++ (Arthur & Vassilvitskii 2007).

    Args:
        x: points, rows L2-normalised.
        k: number of centres, 1 <= k <= n.
        init: centres to keep as the first ones (k0 <= k rows); the rest are sampled.
        generator: CPU generator of the sampling (draws are made on the CPU so that
            every device gives the same centres).

    Returns:
        The centres, rows L2-normalised.

    Shape:
        - x: :math:`(n, D)`, init: :math:`(k_0, D)`, output: :math:`(k, D)`.

    Example:
        >>> x = F.normalize(torch.eye(3), dim=1)
        >>> kmeans_plusplus(x, 3, generator=torch.Generator().manual_seed(0)).abs().sum(0)
        tensor([1., 1., 1.])
    """
    _check(x, k, init)
    if init is not None and init.shape[0] == k:
        return F.normalize(init, dim=1)
    chosen = [] if init is None else [F.normalize(init, dim=1)]
    count = 0 if init is None else init.shape[0]
    if count == 0:
        first = int(torch.randint(x.shape[0], (1,), generator=generator))
        chosen.append(x[first : first + 1])
        count = 1
    centres = torch.cat(chosen)
    # Squared chordal distance to the nearest centre: 2 - 2 max cos.
    dist = (2.0 - 2.0 * (x @ centres.T).amax(dim=1)).clamp_min(0.0)
    new = []
    for _ in range(k - count):
        weights = dist.double().cpu()
        if float(weights.sum()) <= 0.0:  # every point sits on a centre: any point will do
            weights = torch.ones_like(weights)
        pick = int(torch.multinomial(weights, 1, generator=generator))
        new.append(x[pick : pick + 1])
        dist = torch.minimum(dist, (2.0 - 2.0 * (x @ x[pick])).clamp_min(0.0))
    return torch.cat([centres, *new]) if new else centres


def spherical_kmeans(x: torch.Tensor, k: int, init: torch.Tensor | None = None, iters: int = 20,
                     generator: torch.Generator | None = None) -> tuple[torch.Tensor, torch.Tensor]:
    """Cluster unit vectors into `k` unit centres (Lloyd iterations on the sphere).

    Seeds with `kmeans_plusplus` (keeping `init`), then iterates until no
    assignment changes or `iters` rounds. A centre that loses all its points keeps
    its place. Ties go to the lower centre index. Deterministic for a given
    generator state on every device (see `_cluster_sums`).

    Args:
        x: points, rows L2-normalised.
        k: number of centres, 1 <= k <= n.
        init: warm-start centres (k0 <= k rows).
        iters: maximum number of Lloyd rounds.
        generator: CPU generator of the k-means++ seeding.

    Returns:
        (centres, assignment): unit centres and each point's centre index.

    Shape:
        - x: :math:`(n, D)`, output: :math:`(k, D)` and :math:`(n,)`.

    Example:
        >>> x = F.normalize(torch.tensor([[1., .1], [1., -.1], [.1, 1.], [-.1, 1.]]), dim=1)
        >>> centres, assign = spherical_kmeans(x, 2, generator=torch.Generator().manual_seed(0))
        >>> bool(assign[0] == assign[1]) and bool(assign[2] == assign[3]) and bool(assign[0] != assign[2])
        True
    """
    centres = kmeans_plusplus(x, k, init, generator)
    assign = (x @ centres.T).argmax(dim=1)
    for _ in range(iters):
        sums = _cluster_sums(x, assign, k)
        occupied = torch.bincount(assign, minlength=k) > 0
        centres = torch.where(occupied[:, None], F.normalize(sums, dim=1), centres)
        new_assign = (x @ centres.T).argmax(dim=1)
        if torch.equal(new_assign, assign):
            break
        assign = new_assign
    return centres, assign


def _cluster_sums(x: torch.Tensor, assign: torch.Tensor, k: int) -> torch.Tensor:
    """Per-cluster sums of the points, (k, D), in a deterministic order.

    CPU `index_add_` adds sequentially (3x faster here than a matmul); on
    accelerators it uses atomics, whose order varies, so a one-hot product is used.
    """
    if x.device.type == "cpu":
        return torch.zeros(k, x.shape[1], dtype=x.dtype).index_add_(0, assign, x)
    return F.one_hot(assign, k).to(x.dtype).T @ x
