"""The study report names the code it was made with and the code of every run it reads."""
from types import SimpleNamespace

from econet_ros import provenance
from econet_ros.config import Config
from econet_ros.provenance import code, named
from econet_ros.science import report
from econet_ros.science.study import StudySpec, run_codes, run_study


def test_the_report_names_its_code_and_the_code_of_the_study_runs(tmp_path):
    config = Config().replace(**{"evolution.generations": 2, "evolution.population": 4,
                                 "evolution.parents": 2, "evolution.trials": 2,
                                 "evolution.cycles": 5})
    spec = StudySpec(config, 2, 1, {"radius": {"model.object_radius": 4.0}}, 1)
    run_study(spec, tmp_path, jobs=1, progress=False)
    me = (code()["commit"], code()["dirty"])
    assert run_codes(spec, tmp_path) == [me] * (3 * 2 + 3 * 1)   # base study, then the variant
    (tmp_path / "random" / "run-02" / "provenance.json").unlink()     # as made before
    title = report._title(SimpleNamespace(out=tmp_path, spec=spec, swept=[]))
    line = next(line for line in title if line.startswith("**Code**"))
    assert f"this report was made with {named(*me)}; its 9 run(s) with {named(*me)} (8), " \
           "no recorded commit (made before run folders recorded their code) (1)." in line


def test_a_page_made_from_a_dirty_tree_says_so_in_its_first_line(tmp_path, monkeypatch):
    spec = StudySpec(Config(), 1, 1, {}, 1)
    analysis = SimpleNamespace(out=tmp_path, spec=spec, swept=[])
    monkeypatch.setattr(provenance, "code", lambda: {"commit": "0123456789abcdef",
                                                     "dirty": True})
    title = report._title(analysis)
    assert title[0].startswith("**Made from a tree with uncommitted changes** (at "
                               "`0123456789ab`)") and title[1].startswith("# Reproducing")
    monkeypatch.setattr(provenance, "code", lambda: {"commit": "0123456789abcdef",
                                                     "dirty": False})
    assert report._title(analysis)[0].startswith("# Reproducing")
