"""The compiled loops of the onset detector's front end (:mod:`.onsets`: the decimation's filters, step 1's predictor):
each does the same floating-point operations, in the same order, as the code it replaced (scipy's ``sosfilt``,
librosa's ``lpc`` as :func:`._kernels.burg` sums it), so its results are the same to the bit
(tests/test_onsets_front.py holds them against scipy and numpy).

What makes them faster is where the operations run, not what they are:

- :func:`low_pass_two` runs the two decimation filters' eight second-order sections as the eight lanes of one
  vector: at each step section ``s`` takes the sample ``s`` steps behind the first's (the output its predecessor
  gave at the step before). Each lane does what one section of ``sosfilt`` does to its sample, with the vector
  instructions' IEEE arithmetic (no fused multiply-adds), and the loop waits on one section's recursion a
  sample, not on eight sections' worth of instructions.
- :func:`burg` updates an order's prediction errors and adds up the next order's numerator in the same pass.

A module of its own (as :mod:`._kernels`) so that importing :mod:`drumstroke.analysis` does not import numba.
"""

import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic, models, register_model

from .._jit import jit

_LANES = 8  # two filters of four sections each
_DOUBLES = ir.VectorType(ir.DoubleType(), _LANES)
_INT = ir.IntType(32)


class _Lanes(types.Type):
    """Eight doubles held as one LLVM vector (a register, in the loops that carry it)."""

    def __init__(self):
        super().__init__(name="Lanes8")


_lanes_type = _Lanes()


@register_model(_Lanes)
class _LanesModel(models.PrimitiveModel):
    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type, _DOUBLES)


@intrinsic
def _lanes(typingctx, values):
    """A tuple of eight floats as lanes."""
    def codegen(context, builder, signature, args):
        vector = ir.Constant(_DOUBLES, ir.Undefined)
        for lane in range(_LANES):
            vector = builder.insert_element(vector, builder.extract_value(args[0], lane), ir.Constant(_INT, lane))
        return vector
    return _lanes_type(types.UniTuple(types.float64, _LANES)), codegen


@intrinsic
def _lane(typingctx, vector, which):
    """Lane ``which`` of ``vector``."""
    def codegen(context, builder, signature, args):
        return builder.extract_element(args[0], builder.trunc(args[1], _INT))
    return types.float64(_lanes_type, types.intp), codegen


@intrinsic
def _shifted_in(typingctx, y, v):
    """``(v, y0, y1, y2, v, y4, y5, y6)``: each filter's input sample, then its sections' outputs one section on."""
    def codegen(context, builder, signature, args):
        first = builder.insert_element(ir.Constant(_DOUBLES, ir.Undefined), args[1], ir.Constant(_INT, 0))
        order = ir.Constant(ir.VectorType(_INT, _LANES), [_LANES, 0, 1, 2, _LANES, 4, 5, 6])
        return builder.shuffle_vector(args[0], first, order)
    return _lanes_type(_lanes_type, types.float64), codegen


@intrinsic
def _started(typingctx, vector, step):
    """``vector`` with the lanes of sections after ``step`` (in each filter) set to 0: those not yet at a sample."""
    def codegen(context, builder, signature, args):
        section = ir.Constant(ir.VectorType(ir.IntType(64), _LANES), [0, 1, 2, 3, 0, 1, 2, 3])
        step = builder.insert_element(ir.Constant(ir.VectorType(ir.IntType(64), _LANES), ir.Undefined), args[1],
                                      ir.Constant(_INT, 0))
        step = builder.shuffle_vector(step, step, ir.Constant(ir.VectorType(_INT, _LANES), [0] * _LANES))
        return builder.select(builder.icmp_signed("<=", section, step), args[0], ir.Constant(_DOUBLES, 0.0))
    return _lanes_type(_lanes_type, types.intp), codegen


@intrinsic
def _biquads(typingctx, v, b0, b1, b2, a1, a2, z0, z1):
    """:func:`._kernels.biquad` in each lane: the outputs and the new states."""
    def codegen(context, builder, signature, args):
        v, b0, b1, b2, a1, a2, z0, z1 = args
        y = builder.fadd(builder.fmul(b0, v), z0)
        z0 = builder.fadd(builder.fsub(builder.fmul(b1, v), builder.fmul(a1, y)), z1)
        z1 = builder.fsub(builder.fmul(b2, v), builder.fmul(a2, y))
        return context.make_tuple(builder, signature.return_type, [y, z0, z1])
    return types.UniTuple(_lanes_type, 3)(*([_lanes_type] * 8)), codegen


@jit
def _column(sos, other, k):
    """Column ``k`` of the two filters' sections as lanes (``sos``'s four, then ``other``'s)."""
    return _lanes((sos[0, k], sos[1, k], sos[2, k], sos[3, k], other[0, k], other[1, k], other[2, k], other[3, k]))


@jit
def low_pass_two(sos, q, other, q_other, x):
    """``(scipy.signal.sosfilt(sos, x)[::q], scipy.signal.sosfilt(other, x)[::q_other])`` for two filters of 4
    second-order sections each (8th order): the same operations, the eight sections as one vector's lanes."""
    b0, b1, b2 = _column(sos, other, 0), _column(sos, other, 1), _column(sos, other, 2)
    a1, a2 = _column(sos, other, 4), _column(sos, other, 5)
    y = z0 = z1 = _lanes((0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
    n = len(x)
    out = np.empty((n + q - 1) // q)
    out_other = np.empty((n + q_other - 1) // q_other)
    for i in range(3):  # sections not yet at the signal's first sample keep their zero states (as sosfilt's do)
        y, z0, z1 = _biquads(_shifted_in(y, x[i] if i < n else 0.0), b0, b1, b2, a1, a2, z0, z1)
        y, z0, z1 = _started(y, i), _started(z0, i), _started(z1, i)
    skip, skip_other = 0, 0
    for i in range(3, n + 3):  # the last section's output at step i is sample i - 3's
        y, z0, z1 = _biquads(_shifted_in(y, x[i] if i < n else 0.0), b0, b1, b2, a1, a2, z0, z1)
        if skip == 0:
            out[(i - 3) // q] = _lane(y, 3)
            skip = q
        skip -= 1
        if skip_other == 0:
            out_other[(i - 3) // q_other] = _lane(y, 7)
            skip_other = q_other
        skip_other -= 1
    return out, out_other
