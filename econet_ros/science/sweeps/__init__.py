"""The sweep pipeline (`econet sweep`, docs/sweeps.md): spec.py reads a TOML specification into
cells x conditions x seeds, runner.py runs them as Ray tasks, outcomes.py measures each run,
report.py writes the tables, comparisons and figures (figures.py), regime.py applies the
decision rule of docs/analysis.md, and compare.py pairs any two sets of runs (`econet compare`).
ROS-free; only runner.py imports Ray."""
