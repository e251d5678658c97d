"""Path planning on a costmap: OMPL planners and a grid planner with one shared cost model."""
