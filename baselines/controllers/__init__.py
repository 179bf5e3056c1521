"""Controllers that act from the observation and a model of the env: the analytic expert
(SGC) and the comparison baselines (dynamic constraints, minimum jerk)."""
