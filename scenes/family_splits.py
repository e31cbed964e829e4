"""The `family:SEED` buildings' traits and splits, and which scenes are held out (light: no mesh code).

`family:SEED` is a building of the trait family (`scenes.family`): every seed has one trait, fixed by
the seed, chosen so that no single orbit suits them all (a tall tower, a courtyard, a deep U or L plan,
arcades and overhangs, a low wide hall, a walled compound of several buildings). Seeds are split like
`random:SEED`'s: SEED % 5 == 0 is a test building; of the rest, SEED % 5 == 4 is a validation building
and the others are training buildings. The trait `HELD_OUT_TRAIT` is drawn by test seeds only (every
other test seed), so a policy meets it first on a test building; the other traits cycle through each
split in `SEEN_TRAITS`' order.
"""

from __future__ import annotations

TRAITS = ("tower", "courtyard", "u_plan", "l_plan", "arcade", "hall", "compound")
"""Every trait of the family."""
HELD_OUT_TRAIT = "compound"
"""The trait no training or validation seed draws (a walled compound of several buildings)."""
SEEN_TRAITS = tuple(trait for trait in TRAITS if trait != HELD_OUT_TRAIT)
"""The traits of training and validation seeds, in the order they cycle."""
FAMILY_PREFIX = "family:"
"""`family:SEED` names a building of the trait family."""
SPLITS = ("train", "validation", "test")
"""The splits of `family:SEED`."""
HELD_OUT_PRESETS = ("alpine_chalet", "imperial_temple")
"""The presets no run trains, tunes or chooses on."""


def family_split(seed: int) -> str:
    """'train', 'validation' or 'test': the split of `family:SEED`."""
    if seed < 0:
        raise ValueError(f"family seed must be non-negative, got {seed}")
    return {0: "test", 4: "validation"}.get(seed % 5, "train")


def family_trait(seed: int) -> str:
    """The trait of `family:SEED` (test seeds alternate the held-out trait with the others)."""
    split, block, rest = family_split(seed), seed // 5, seed % 5
    if split == "train":
        return SEEN_TRAITS[(3 * block + rest - 1) % len(SEEN_TRAITS)]
    if split == "validation":
        return SEEN_TRAITS[block % len(SEEN_TRAITS)]
    return HELD_OUT_TRAIT if block % 2 == 0 else SEEN_TRAITS[(block // 2) % len(SEEN_TRAITS)]


def family_seeds(split: str, count: int, trait: str | None = None, start: int = 0) -> list[int]:
    """The first `count` seeds >= `start` of `split` (and of `trait`, if given)."""
    if split not in SPLITS:
        raise ValueError(f"split must be one of {', '.join(SPLITS)}, got {split!r}")
    if trait is not None and trait not in TRAITS:
        raise ValueError(f"unknown trait {trait!r}; traits: {', '.join(TRAITS)}")
    if trait == HELD_OUT_TRAIT and split != "test":
        raise ValueError(f"the held-out trait {trait!r} has no {split} seeds, only test seeds")
    seeds, seed = [], start
    while len(seeds) < count:
        if family_split(seed) == split and trait in (None, family_trait(seed)):
            seeds.append(seed)
        seed += 1
    return seeds


def parse_family(spec: str) -> int:
    """The SEED of a `family:SEED` scene name.

    Raises:
        ValueError: not `family:` followed by a non-negative integer.
    """
    seed = spec[len(FAMILY_PREFIX):] if spec.startswith(FAMILY_PREFIX) else ""
    if not (seed.isascii() and seed.isdigit()):  # isdigit alone takes '²', which int() refuses
        raise ValueError(f"bad scene {spec!r}: expected family:SEED with SEED a non-negative integer "
                         f"(e.g. family:{family_seeds('train', 1)[0]})")
    return int(seed)


def held_out(scene: str) -> bool:
    """Whether `scene` is a held-out test building: a held-out preset, a test-split `random:SEED`, or a
    `family:SEED` of the test split (which holds every building of the held-out trait)."""
    if scene in HELD_OUT_PRESETS:
        return True
    name, _, seed = scene.partition(":")
    if name == "random" and seed.isdigit():
        from scenes.presets import seed_split

        return seed_split(int(seed)) == "test"
    if scene.startswith(FAMILY_PREFIX):
        seed_value = parse_family(scene)
        return family_split(seed_value) == "test" or family_trait(seed_value) == HELD_OUT_TRAIT
    return False
