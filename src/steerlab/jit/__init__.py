"""steerlab's compile boundary: everything that compiles, caches and calls machine code.

The rest of steerlab writes plain ``@numba.njit`` kernels and asks this package for the
compiled loops that join them. Here, and only here, live:

* the generated drivers and their templates (:mod:`~steerlab.jit.drivers`,
  :mod:`~steerlab.jit.driver_template`, :mod:`~steerlab.jit.controller_step_template`,
  :mod:`~steerlab.jit.env_template`, :mod:`~steerlab.jit.controller_calls`);
* how a kernel is named across processes and which user sources key it
  (:mod:`~steerlab.jit.kernel_refs`, :mod:`~steerlab.jit.kernel_sources`);
* the glue to numba's on-disk cache (:mod:`~steerlab.jit.numba_cache`,
  :mod:`~steerlab.jit.numba_cache_load`: steerlab's own kernels load without numba's
  compile-time registries, :mod:`~steerlab.jit.disk_memo`);
* calls into compiled code by address (:mod:`~steerlab.jit.numba_call_at`) and the
  counter-based random numbers built from one LLVM instruction (:mod:`~steerlab.jit.philox`);
* what the rest of steerlab may ask about compiled functions (:mod:`~steerlab.jit.dispatch`);
* the numba versions whose internals steerlab may use (:mod:`~steerlab.jit.numba_gate`);
* the ``steerlab`` command's process-wide settings (:mod:`~steerlab.jit.command`): numba's
  threading layer (:mod:`~steerlab.jit.threading_layer`), OpenBLAS threads
  (:mod:`~steerlab.jit.blas_threads`), numba's BLAS probe (:mod:`~steerlab.jit.numba_blas_probe`),
  and the command's fast exit (:mod:`~steerlab.jit.fast_exit`), made by the command only:
  ``import steerlab`` changes nothing outside steerlab.

It is the only package that may use numba's or another library's internals or change another
library's modules (``tests/test_layering.py`` enforces it).
"""
