"""The reliability probe of issue 28 (run by `scripts/reliability_probe.py`): a harness, one module per
part (kills, writers, disk, resume, readers, policy files, meshes, command-line values) and the runner."""
