"""The pytest plugin: scenario YAML files collected and run as test items."""

from __future__ import annotations

import pytest
from task_fixtures import scenario_dict, write_scenario

from lynxplan.pytest_plugin import ExpectationFailedError, check_scenario_file

pytest_plugins = ["pytester"]


@pytest.fixture(scope="module", autouse=True)
def _imported(tmp_path_factory):
    """Run one scenario in this process first: pytester's in-process runs drop the modules they
    import, and numba cannot register its extensions twice in one process."""
    path = tmp_path_factory.mktemp("warm") / "warm.yaml"
    check_scenario_file(write_scenario(path, scenario_dict(sample_rate=50)))


@pytest.fixture
def scenario_folder(pytester):
    folder = pytester.mkdir("scenarios")
    good = scenario_dict(compare=False, sample_rate=50)
    write_scenario(folder / "good.yaml", good)
    bad = scenario_dict(compare=False, sample_rate=50, expect={"min_clearance": ">= 20 in"})
    write_scenario(folder / "too_strict.yaml", bad)
    broken = scenario_dict(compare=False)
    broken["segments"][1]["to"] = "nowhere"
    write_scenario(folder / "broken.yaml", broken)
    (folder / "settings.yaml").write_text("colour: red\n")  # no kind: not a scenario
    (folder / "notes.txt").write_text("kind: task\n")
    return folder


def test_collects_scenarios_once_and_reports_failures(pytester, scenario_folder):
    result = pytester.runpytest("scenarios", "-p", "no:cacheprovider")
    result.assert_outcomes(passed=1, failed=2)
    result.stdout.fnmatch_lines(
        [
            "*broken.yaml, segments?1?.to: unknown waypoint 'nowhere'*",
            "*too_strict.yaml: 1 expectation(s) failed:*",
            "*- min_clearance: measured * in, expected >= 20 in*",
        ]
    )
    collected = pytester.runpytest("scenarios", "--collect-only", "-q", "-p", "no:cacheprovider")
    collected.stdout.fnmatch_lines(["scenarios/broken.yaml::scenario", "3 tests collected*"])


def test_yaml_given_on_the_command_line_is_collected(pytester):
    path = write_scenario(pytester.path / "elsewhere.yaml", scenario_dict(compare=False))
    result = pytester.runpytest(str(path), "-p", "no:cacheprovider")
    result.assert_outcomes(passed=1)
    # The same file is not collected when only its folder is given (not a scenarios folder).
    result = pytester.runpytest(str(pytester.path), "-p", "no:cacheprovider")
    result.assert_outcomes()


def test_check_function_raises_with_the_failures(tmp_path):
    path = write_scenario(
        tmp_path / "s.yaml",
        scenario_dict(compare=False, expect={"max_duration": "<= 3 s", "within_limits": True}),
    )
    with pytest.raises(
        ExpectationFailedError, match=r"1 expectation\(s\) failed:\n  - max_duration"
    ):
        check_scenario_file(path)
