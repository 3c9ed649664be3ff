"""One simulated UAV: a MAVLink 2 endpoint over UDP with the paper's sensor models."""
