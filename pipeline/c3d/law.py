"""F(t), the friction coefficient as a function of the slip t = |u_t|, from a scene's [friction] table.

The same formulas and defaults as solver/friction/friction_law.cpp and solver/model/scene.cpp:
ramp (6.1): F = high for t <= t0, low for t >= t0 + 2/param, linear between; table: piecewise linear
through [t, F] points, constant beyond the ends, a repeated t is a jump.
"""
import bisect


def coefficient(friction):
    """F as a function of one slip value t (float -> float) for the [friction] table `friction`."""
    law = friction.get("law", "none")
    if law == "none" or float(friction.get("slip_bound", 0)) == 0:
        return lambda t: 0.0
    if law == "constant":
        value = float(friction.get("value", 0))
        return lambda t: value
    if law == "ramp":
        high, low = float(friction.get("high", 0.3)), float(friction.get("low", 0.2))
        t0, param = float(friction.get("t0", 1e-5)), float(friction.get("param", 6e4))
        width = 2.0 / param

        def ramp(t):
            s = min(1.0, max(0.0, (t - t0) / width))
            return high + (low - high) * s
        return ramp
    if law == "table":
        pts = [(float(t), float(f)) for t, f in friction["points"]]
        ts = [p[0] for p in pts]

        def table(t):
            if t <= ts[0]:
                return pts[0][1]
            if t >= ts[-1]:
                return pts[-1][1]
            j = bisect.bisect_right(ts, t)  # ts[j-1] <= t < ts[j]
            (ta, fa), (tb, fb) = pts[j - 1], pts[j]
            return fa + (fb - fa) * (t - ta) / (tb - ta)
        return table
    raise ValueError(f"unknown friction law '{law}'")
