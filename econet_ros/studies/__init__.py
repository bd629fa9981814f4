"""The studies wing: the pre-registered studies of this project (docs/preregistrations.md), built
on the library beside it and never imported by it. regime.py and confirm.py (finding the paper's
regime; the confirmatory study H1-H3 and the readings), experiments.py (E1-E3's hypotheses) and
family.py (their page, Holm over the family), transplant.py (E2's and E6's transplant arms),
holding_mechanism.py (E5: whether touch silences a champion's last hidden layer),
robustness.py and maintenance.py (E6's mutational-robustness assay; E6's criteria),
slowdown_claims.py (E8 and E9 from a study's claims) and second_family.py (the E5-E9 page, with
E7's criteria in experiments.py). A study of
your own can live the same way, in any package: see docs/sweeps.md. ROS-free."""
