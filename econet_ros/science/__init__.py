"""The science: the paper's measures, the lesion, the study of its three conditions, the claims
of its Results section with their rules, the figures and the report. ROS-free."""
