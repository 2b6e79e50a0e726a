"""Folds of limit cycles in two parameters (issue 27, item 1) through
`hb.cycle_fold_curve` on x'' - (mu + nu x^2 - x^4) x' + x = 0: the fold's mu
at nu = 0.5 and 1, quoted from crates/ivt-hb/tests/cycle_fold.rs, where they
match RK4 shooting on (x0, T, mu) (independent of HB) to 1e-8."""
from ivt import hb


def family(mu, nu):
    return (1.0, -mu, 1.0, lambda x, v, th: -(nu * x * x - x**4) * v, None)


def test_cycle_fold_curve_matches_shooting_reference():
    curve = hb.cycle_fold_curve(family, 1.0, 0.45, -0.2, 0.1, at=[0.5], n=25, samples=128,
                                vectorized=True)
    assert curve["termination"] == "left_interval", curve["termination"]
    assert curve["special"] == [] and curve["unlocated"] == []
    first = curve["points"][0]
    assert first["nu"] == 1.0 and abs(first["mu"] - -0.124993216903) < 1e-8, first["mu"]
    [at] = curve["at"]
    assert at["nu"] == 0.5 and abs(at["mu"] - -0.031249894035) < 1e-8, at["mu"]
    # Averaging: the fold's amplitude is about sqrt(nu).
    assert abs(at["amplitude"] - 0.5**0.5) < 0.05, at["amplitude"]


def test_cycle_fold_curve_refuses_equal_bounds():
    try:
        hb.cycle_fold_curve(family, 1.0, 1.0, -0.2, 0.1)
    except ValueError as e:
        assert "nu_from" in str(e)
    else:
        raise AssertionError("equal nu bounds must be refused")


def test_cycle_fold_curve_reraises_the_family_exception():
    """An exception `family` raises during the curve (ν ≠ nu_from) is the
    error, not the failed point it caused."""

    class Boom(Exception):
        pass

    def failing(mu, nu):
        if nu < 0.9:
            raise Boom(f"no system at nu = {nu}")
        return family(mu, nu)

    try:
        hb.cycle_fold_curve(failing, 1.0, 0.45, -0.2, 0.1, n=25, samples=128, vectorized=True)
    except Boom as e:
        assert "no system at nu" in str(e)
    else:
        raise AssertionError("the family's exception must be re-raised")
