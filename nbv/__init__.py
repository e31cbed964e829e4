"""Next-best-view planning: features, Bag of Views, refinement, RL, reconstruction, metrics."""
