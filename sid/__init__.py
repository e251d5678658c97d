"""sid: social interaction detection from a single RGB-D camera.

Data flows one way: source -> pose -> people -> groups -> costmap layers -> planner -> metrics/pictures.
Each stage lives in its own module and can be used alone.
"""

__version__ = "0.1.0"
