"""The estimator methods by name (registry) and the compiled steps of those that are not a
sensor-frame LTI filter: the local-density Wiener filter, Luinge, Mahony, Tseng's adaptive switch."""
