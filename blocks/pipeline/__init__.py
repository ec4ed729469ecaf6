"""The causal pipeline (causal: the order of the stages) and its two drivers: over whole
arrays with the offline additions (batch), and one sample at a time (online)."""
