"""IMU recordings in and estimates out: readers (CSV, BROAD .mat), checks of units, axes,
gaps and ranges, and the estimate writer."""
