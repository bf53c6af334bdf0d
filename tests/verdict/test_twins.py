"""Common-noise twins (chaoscam/verdict/_twins.py): runs sharing the draws converge where the
random system's top exponent is negative and separate where it is positive; a pair whose
contacts part stops sharing the draws, which the test reports."""

import chaoscam
from chaoscam.verdict import twin_test


def _twins(delta, **changes):
    run = chaoscam.simulate(duration=40.0, transient=20.0, series=False, **changes)
    pts = run.section[["theta_f", "omega_f"]].to_numpy()
    return twin_test(run.params, run.numerics, pts[[len(pts) // 2, -1]], seed=0, index=0,
                     delta=delta)  # fmt: skip


def test_twins_of_a_synchronised_response_converge():
    """xi = 0.2, sigma = 2 mm (the random set's periodic 1): twins 1e-6 rad apart end below
    1e-7 of their start, the draws shared throughout."""
    tw = _twins(1e-6, xi=0.2, l_lambda_sigma=0.002)
    assert tw.outcome == "synchronised" and max(tw.ratios) < 1e-7
    assert tw.split_at == (None, None) and tw.exponent < 0


def test_twins_of_random_chaos_separate():
    """Table 1 at sigma = 2 mm (the random set's chaotic): twins 1e-8 rad apart grow over
    100-fold, sharing the draws; the rate is positive."""
    tw = _twins(1e-8, l_lambda_sigma=0.002)
    assert tw.outcome == "separated" and min(tw.ratios) > 100 and tw.exponent > 0


def test_a_pair_whose_contacts_part_is_reported_and_judged_on_its_growth():
    """omega = 38, sigma = 2 mm (broad chaos): once the twins have separated their contacts
    differ and the draws are no longer shared (split_at); the growth came first, so the pair
    still counts as separated, and the detail says the draws parted."""
    tw = _twins(1e-8, omega=38.0, l_lambda_sigma=0.002)
    assert all(s is not None for s in tw.split_at) and tw.outcome == "separated"
    assert "stopped sharing the draws" in tw.detail


def test_a_failed_twin_run_leaves_the_test_inconclusive(monkeypatch):
    """A twin run that does not end normally: inconclusive, never a label."""
    from chaoscam.verdict import _twins as module

    real = module.solve

    def failing(*args, **kw):
        sol = real(*args, **kw)
        sol.members.loc[1, "status"] = "LEFT_REACH"
        return sol

    monkeypatch.setattr(module, "solve", failing)
    tw = _twins(1e-6, xi=0.2, l_lambda_sigma=0.002)
    assert tw.outcome == "inconclusive" and "did not end normally" in tw.detail
