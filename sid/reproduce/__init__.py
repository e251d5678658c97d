"""Reproduction of the paper's results: ``sid reproduce table1`` and ``sid reproduce navigation``.

- ``table1``: accuracy of people and groups on the synthetic layouts S1-S5 vs the paper's Table 1.
- ``navigation``: the demo's with/without-recognition comparison over a family of tasks, per planner.
- ``report``: markdown, JSON and progress output of both; ``plot``: the navigation chart (OpenCV).

How to run them and how to read their outputs: docs/reproduction.md.
"""
