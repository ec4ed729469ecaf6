"""The estimator methods by name (registry; their steps are the C core's, blocks/core/methods)
and the model of the local-density Wiener filter (wiener_local)."""
