"""cases.outburst.convergence's ensemble table on made-up rows: each
quantity's mean and interval by cell, and the verdict on the two finest cells
(Welch's t-test at 5 %), whatever order the cells came in."""
from cases.outburst.convergence import QUANTITIES, ensemble_table, measured


def rows_for(cell, values):
    """A row per seed at t = 0.5 s, every quantity taking the seed's value."""
    return [{"law": "crack_band", "cell": cell, "seed": k + 1, "time_s": 0.5, **{q: v for q, _ in QUANTITIES}}
            for k, v in enumerate(values)]


def verdicts(rows):
    table = ensemble_table(rows, "crack_band", 0.5, 3)
    return [line.rsplit("|", 2)[-2].strip().split(":")[0] for line in table
            if line.startswith("| ") and "(" in line and "quantity" not in line]


def test_means_within_their_spread_do_not_differ():
    rows = rows_for("1/6 m", [1.0, 1.2, 0.9, 1.1]) + rows_for("1/8 m", [1.05, 1.15, 0.95, 1.0])
    assert verdicts(rows) == ["no"] * len(QUANTITIES)


def test_means_apart_differ_and_say_how_far():
    # The finer cell first: the two finest are found by size, not by order.
    rows = rows_for("1/8 m", [2.0, 2.01, 1.99, 2.0]) + rows_for("1/6 m", [1.0, 1.01, 0.99, 1.0]) + \
        rows_for("1/4 m", [2.0, 2.0, 2.0])
    assert verdicts(rows) == ["yes"] * len(QUANTITIES)
    assert "means 1 apart" in ensemble_table(rows, "crack_band", 0.5, 3)[4]


def test_one_seed_gives_no_verdict():
    rows = rows_for("1/6 m", [1.0]) + rows_for("1/8 m", [1.1, 1.0])
    table = ensemble_table(rows, "crack_band", 0.5, 3)
    assert all(line.endswith("- (fewer than two seeds) |") for line in table[4:])


def test_a_failed_seed_is_listed_and_left_out():
    rows = rows_for("1/6 m", [1.0, 1.2]) + rows_for("1/8 m", [1.1, 1.0])
    rows.append({"law": "crack_band", "cell": "1/8 m", "seed": 3, "failure": "mpm: the energy is exploding"})
    table = ensemble_table(rows, "crack_band", 0.5, 3)
    assert all("(2)" in line for line in table[4:4 + len(QUANTITIES)])
    assert table[-1].endswith("1/8 m, seed 3: mpm: the energy is exploding")


def test_a_run_not_made_is_a_failure_row():
    assert measured(None, "nowhere", {"law": "local", "cell": "1/8 m"}, [0.5]) == [
        {"law": "local", "cell": "1/8 m", "failure": "not run (--measure-only)"}]
