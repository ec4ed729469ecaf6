"""Earth-frame attitude filters (Rizun eqs. 25, 33, 34, §4.2; Tseng's complementary pairs),
their sensor-frame transformation (eq. 35) and their analytic accuracy (§3.4)."""
