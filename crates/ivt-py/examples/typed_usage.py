"""A typed use of the `ivt` package: checked by `mypy --strict` in CI
(scripts/py-test) so the stubs stay true to the API."""

import numpy as np
import numpy.typing as npt

import ivt


def plant_speed_profile(r: float) -> npt.NDArray[np.float64]:
    """Output speed over one revolution of the driven gear at ω = 10 rad/s."""
    theta = np.linspace(0.0, 2.0 * np.pi, 361)
    w_u: npt.NDArray[np.float64] = ivt.kin.output_speed(theta, 10.0, r)
    return w_u


def main() -> None:
    plant = ivt.kin.Plant(r_a=0.25, gravity="roller_mass")
    scalar: float = ivt.kin.f(0.3)
    terms = plant.terms(np.linspace(0.0, 1.0, 5), 0.006, 7.0, 4.0)
    print(f"f(0.3) = {scalar:.6f}, J = {terms['j'].round(5)}")
    print(f"max ω_U = {plant_speed_profile(0.006).max():.4f} rad/s")

    k, k2 = ivt.ctrl.thesis_gains(0.06, 0.12)
    controller = ivt.ctrl.Controller(1200, k=k, k2=k2, law="delay")
    ticks = np.cumsum(np.full(3000, 500, dtype=np.int64))  # 10.47 rad/s at 1 MHz
    out = controller.on_pulses(ticks)
    print(f"ω_a = {float(out['omega_a'][-1]):.3f} rad/s, r = {float(out['r'][-1]) * 1e3:.3f} mm")


if __name__ == "__main__":
    main()
