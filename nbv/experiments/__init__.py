"""The paper's experiments: its numbers, the demo, Table 2 and planner comparisons (each a config + a run)."""
