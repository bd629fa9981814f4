"""The reference model: a second, independent reading of the paper in plain NumPy, the oracle
the engine is held against (tests/core/test_reference_model.py) and the independent check of a
sweep's champions (``econet check``, econet_ros/science/reference_check.py). model.py runs one
trial, evolution.py the variation and selection, partings.py says where the engine's course of
a trial and the reference's part and why. Its worth is its independence: it imports nothing of
the package but the settings' dataclasses (econet_ros.config; tests/core/test_layout.py holds
it to that)."""
