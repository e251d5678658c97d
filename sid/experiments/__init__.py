"""Experiments on top of the library: the with/without comparison, the demo, reproductions, benchmarks."""
