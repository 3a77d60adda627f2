r"""Call a compiled numba function through its machine-code address, from compiled code.

Why: a numba function that calls another compiled function links a copy of the callee's LLVM
IR into its own module and optimises and compiles that copy again. For a small wrapper around a
big kernel (the Gymnasium environments' threaded step, a ``prange`` over ranges of lanes, each
running the one-call step of :mod:`steerlab.jit.env_template`) that repeats the kernel's whole
compile: seconds per (ship, guidance) pair. Calling the callee's machine code through its
address instead, the wrapper compiles in a fraction of a second and the callee's code is the
one already compiled (or loaded from the cache), so the numbers are those of a direct call.

:func:`call_at` (a numba intrinsic, usable only in compiled code) calls the function at an
address with numba's own calling convention; :func:`address_of` (Python) gives the address of a
dispatcher's compiled overload for given argument types. numba's first-class functions
(``types.FunctionType``) do the same but look the address up from Python on every call
(about 10-20 us, more than a threaded step's hand-over is worth).

The caller guarantees that the argument types at the :func:`call_at` site are those the
address was taken for (:func:`address_of` takes them from the very arguments the compiled caller
receives); a mismatch is undefined behaviour, as with any function pointer.
"""

from __future__ import annotations

from typing import Any

from numba import types
from numba.core import cgutils, errors
from numba.extending import intrinsic


@intrinsic
def call_at(typingctx, address, args):
    """``f(*args)`` for the compiled numba function ``f`` at ``address`` (int64, from
    :func:`address_of`), returning its int64 result; ``args`` a tuple. An exception raised by
    ``f`` propagates to the caller."""
    if not isinstance(address, types.Integer) or not isinstance(args, types.BaseTuple):
        return None
    argtys = tuple(args.types)
    sig = types.int64(address, args)

    def codegen(context, builder, signature, llargs):
        addr, tup = llargs
        return _call(context, builder, addr, types.int64, argtys, cgutils.unpack_tuple(builder, tup, len(argtys)))

    return sig, codegen


def _call(context, builder, addr, restype, argtys, values):
    """Call the function at ``addr`` in numba's calling convention; an exception it raised
    propagates to the caller."""
    fnty = context.call_conv.get_function_type(restype, argtys)
    callee = builder.inttoptr(addr, fnty.as_pointer())
    status, result = context.call_conv.call_function(builder, callee, restype, argtys, values)
    with cgutils.if_unlikely(builder, status.is_error):
        context.call_conv.return_status_propagate(builder, status)
    return result


def address_of(dispatcher: Any, argtypes: tuple) -> int:
    """The machine-code address of ``dispatcher``'s overload for the numba types ``argtypes``
    (compiled, or loaded from numba's cache, first if needed); its return type must be int64
    (what :func:`call_at` reads). The dispatcher keeps the code alive: keep it referenced."""
    return typed_address(dispatcher, types.int64, argtypes)


def typed_call(restype, argtypes: tuple):
    """A :func:`call_at` for callees of one fixed signature ``restype(*argtypes)``:
    ``call(address, args)`` returns the callee's ``restype`` value (``none`` for a function
    without one). Each argument at the call site is cast to its declared type (e.g. an integer
    to a float), so callers whose argument types differ a little still call the one compiled
    callee; an argument that cannot be cast is a typing error of the caller (not
    undefined behaviour). ``address`` must come from :func:`typed_address` with the same
    ``argtypes``."""
    declared = tuple(argtypes)

    @intrinsic
    def call(typingctx, address, args):
        if not isinstance(address, types.Integer) or not isinstance(args, types.BaseTuple):
            return None
        site = tuple(args.types)
        if len(site) != len(declared) or any(typingctx.can_convert(a, b) is None
                                             for a, b in zip(site, declared)):
            raise errors.TypingError(f"call by address: arguments {site} cannot be cast to {declared}")

        def codegen(context, builder, signature, llargs):
            addr, tup = llargs
            values = [context.cast(builder, v, a, b)
                      for v, a, b in zip(cgutils.unpack_tuple(builder, tup, len(site)), site, declared)]
            result = _call(context, builder, addr, restype, declared, values)
            return result if restype != types.none else context.get_dummy_value()

        return restype(address, args), codegen

    return call


def typed_address(dispatcher: Any, restype, argtypes: tuple) -> int:
    """The machine-code address of ``dispatcher``'s overload for ``argtypes`` (compiled, or
    loaded from numba's cache, first if needed), for a :func:`typed_call` of that signature;
    ``TypeError`` if it returns another type. Keep the dispatcher referenced."""
    dispatcher.compile(tuple(argtypes))
    cres = dispatcher.overloads[tuple(argtypes)]
    if types.unliteral(cres.signature.return_type) != restype:
        raise TypeError(f"{dispatcher.py_func.__name__} returns {cres.signature.return_type}, "
                        f"its callers read {restype}")
    return int(cres.library.get_pointer_to_function(cres.fndesc.llvm_func_name))


@intrinsic
def data_address(typingctx, arr):
    """The address (int64) of the first element of a C-contiguous array; a typing error for any
    other layout (whose elements are not one block from there)."""
    if not isinstance(arr, types.Array) or arr.layout != "C":
        if isinstance(arr, types.Array):
            raise errors.TypingError(f"data_address: the array must be C-contiguous, not {arr}")
        return None

    def codegen(context, builder, signature, llargs):
        ary = context.make_array(arr)(context, builder, llargs[0])
        return builder.ptrtoint(ary.data, context.get_value_type(types.int64))

    return types.int64(arr), codegen


@intrinsic
def row_address(typingctx, arr, i):
    """The address (int64) of row ``i`` of a C-contiguous 2-D array (no view is made)."""
    if not isinstance(arr, types.Array) or arr.ndim != 2 or not isinstance(i, types.Integer):
        return None
    if arr.layout != "C":
        raise errors.TypingError(f"row_address: the array must be C-contiguous, not {arr}")

    def codegen(context, builder, signature, llargs):
        ary = context.make_array(arr)(context, builder, llargs[0])
        i64 = context.get_value_type(types.int64)
        row = context.cast(builder, llargs[1], i, types.int64)
        stride = cgutils.unpack_tuple(builder, ary.strides, 2)[0]
        return builder.add(builder.ptrtoint(ary.data, i64), builder.mul(row, stride))

    return types.int64(arr, i), codegen


@intrinsic
def float64_pointer(typingctx, address):
    """``address`` (int64) as a pointer to float64, for ``numba.carray(pointer, n)``."""
    if not isinstance(address, types.Integer):
        return None

    def codegen(context, builder, signature, llargs):
        return builder.inttoptr(llargs[0], context.get_value_type(types.CPointer(types.float64)))

    return types.CPointer(types.float64)(address), codegen
