"""steerlab's parts as objects for other people's loops.

* :mod:`.design` - a :class:`~steerlab.control.design_context.DesignContext` from a catalogue
  ship at a speed, from Nomoto ``(K, T)`` alone, or from nothing (fixed-gain laws);
* :mod:`.controller` - :func:`controller`: one autopilot, stepped sample by sample;
* :mod:`.controller_vector` - N autopilots stepped in one compiled call;
* :mod:`.ship` - :func:`ship`: a ship + steering gear, stepped by RK4;
* :mod:`.linear` - python-control systems of ships and linear controllers.

Every object calls the very kernels the engines call, so its numbers are the engines' numbers.
"""
