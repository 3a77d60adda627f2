"""Sensor models: heading / yaw-rate noise, sample rate, quantisation and dropouts (``[sensors]``)."""
