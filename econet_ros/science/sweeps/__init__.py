"""The sweep pipeline (`econet sweep`, docs/sweeps.md): spec.py reads a TOML specification into a
plan of cells x conditions x seeds (plan.py), runner.py runs them as Ray tasks, outcomes.py
measures each run, report.py writes the tables, comparisons and figures (figures.py), the
decision rule the spec names applies its own (rules.py; our studies' rules live in
econet_ros/studies), and compare.py pairs any two sets of runs (`econet compare`). ROS-free; only runner.py imports Ray."""
