"""The compiled loops of the onset detector's front end (:mod:`.onsets`: the high-pass, the decimation and its filters,
steps 1-3's predictor, jumps and peaks): each does the same floating-point operations, in the same order, as the code
it replaced (scipy's ``sosfilt`` and ``lfilter``, librosa's ``lpc`` with its sums in four lanes, ``peak_pick``), so its
results are the same to the bit (tests/test_onsets_front.py holds them against scipy, numpy and librosa).

What makes them faster is where the operations run, not what they are:

- Vectors of lanes (LLVM's, through numba's intrinsics: numba does not vectorise these loops itself), each lane
  doing what one scalar did, with IEEE arithmetic (no fused multiply-adds): :func:`low_pass_three` runs the two
  decimation filters' eight second-order sections as the eight lanes of one vector (the level band's four in
  another's), section ``s`` a sample behind section ``s - 1`` (the output it gave at the step before), so the loop
  waits on one section's recursion a sample, not on twelve sections' instructions; a sum added in four lanes (every fourth term) is one vector's four lanes;
  :func:`prediction_error` holds 32 outputs in eight vectors over all its taps.
- Work that waits on different units side by side: the filters wait on their recursions, the jump profile on the
  divider (:func:`low_pass_three_and_jumps`); the high-pass on its recursion, its largest sample on nothing
  (:func:`high_pass`).
- Fewer passes: Burg's update of an order's errors and the next order's numerator in one pass (:func:`burg`); the
  peak picker's scans for a larger or an equal sample four samples a comparison, a stretch under the least asked
  sixteen (:func:`peak_pick_over`).

A module of its own (as :mod:`._kernels`) so that importing :mod:`drumstroke.analysis` does not import numba.
"""

import numpy as np
from llvmlite import ir
from numba import types
from numba.core import cgutils
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
def _zeroed(typingctx, vector, step):
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


_QUAD = ir.VectorType(ir.DoubleType(), 4)
_AHEAD = 8  # how far the running power is added ahead of the jumps that read it: a vector read of four values just stored
# one by one waits for the stores to finish


class _Quad(types.Type):
    """Four doubles held as one LLVM vector: a sum's four lanes (every fourth term), or four samples."""

    def __init__(self):
        super().__init__(name="Quad")


_quad_type = _Quad()


@register_model(_Quad)
class _QuadModel(models.PrimitiveModel):
    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type, _QUAD)


def _doubles(array, writeable=False):
    """``array``'s type, when it is a contiguous 1-D array of doubles (read only or not; written: not read only): the
    vectors' loads and stores read and write four in a row."""
    if not (isinstance(array, types.Array) and array.dtype == types.float64 and array.ndim == 1 and array.layout == "C"
            and (array.mutable or not writeable)):
        raise TypeError(f"a contiguous 1-D array of float64{' (writeable)' if writeable else ''}, got {array}")
    return array


def _quad_pointer(context, builder, array_type, array, start):
    data = context.make_array(array_type)(context, builder, array).data
    return builder.bitcast(builder.gep(data, [start]), _QUAD.as_pointer())


@intrinsic
def _load(typingctx, array, start):
    """``array[start:start + 4]`` (a contiguous array of doubles) as a quad."""
    def codegen(context, builder, signature, args):
        return builder.load(_quad_pointer(context, builder, signature.args[0], args[0], args[1]), align=8)
    return _quad_type(_doubles(array), types.intp), codegen


@intrinsic
def _store(typingctx, array, start, quad):
    """``array[start:start + 4] = quad``."""
    def codegen(context, builder, signature, args):
        builder.store(args[2], _quad_pointer(context, builder, signature.args[0], args[0], args[1]), align=8)
        return context.get_dummy_value()
    return types.none(_doubles(array, writeable=True), types.intp, _quad_type), codegen


@intrinsic
def _quad(typingctx, value):
    """``value`` in each of four lanes."""
    def codegen(context, builder, signature, args):
        quad = builder.insert_element(ir.Constant(_QUAD, ir.Undefined), args[0], ir.Constant(_INT, 0))
        return builder.shuffle_vector(quad, quad, ir.Constant(ir.VectorType(_INT, 4), [0] * 4))
    return _quad_type(types.float64), codegen


@intrinsic
def _lane4(typingctx, quad, which):
    """Lane ``which`` of a quad."""
    def codegen(context, builder, signature, args):
        return builder.extract_element(args[0], builder.trunc(args[1], _INT))
    return types.float64(_quad_type, types.intp), codegen


@intrinsic
def _times(typingctx, x, y):
    """``x * y`` in each lane."""
    def codegen(context, builder, signature, args):
        return builder.fmul(args[0], args[1])
    return _quad_type(_quad_type, _quad_type), codegen


@intrinsic
def _plus(typingctx, x, y):
    """``x + y`` in each lane."""
    def codegen(context, builder, signature, args):
        return builder.fadd(args[0], args[1])
    return _quad_type(_quad_type, _quad_type), codegen


@intrinsic
def _plus_times(typingctx, x, y, z):
    """``x + y * z`` in each lane (a product, then a sum: no fused multiply-add)."""
    def codegen(context, builder, signature, args):
        return builder.fadd(args[0], builder.fmul(args[1], args[2]))
    return _quad_type(_quad_type, _quad_type, _quad_type), codegen


@intrinsic
def _after(typingctx, last, quad):
    """``(last[3], quad[0], quad[1], quad[2])``."""
    def codegen(context, builder, signature, args):
        return builder.shuffle_vector(args[0], args[1], ir.Constant(ir.VectorType(_INT, 4), [3, 4, 5, 6]))
    return _quad_type(_quad_type, _quad_type), codegen


@intrinsic
def _sum_of_lanes(typingctx, quad):
    """``(quad[0] + quad[1]) + (quad[2] + quad[3])``."""
    def codegen(context, builder, signature, args):
        lane = [builder.extract_element(args[0], ir.Constant(_INT, k)) for k in range(4)]
        return builder.fadd(builder.fadd(lane[0], lane[1]), builder.fadd(lane[2], lane[3]))
    return types.float64(_quad_type), codegen


@intrinsic
def _first_lane_plus(typingctx, quad, value):
    """``quad`` with ``value`` added to its first lane."""
    def codegen(context, builder, signature, args):
        zero = ir.Constant(_INT, 0)
        return builder.insert_element(args[0], builder.fadd(builder.extract_element(args[0], zero), args[1]), zero)
    return _quad_type(_quad_type, types.float64), codegen


def _lanes_compared(predicate):
    """An intrinsic: the lanes of ``x[start:start + 4]`` (a contiguous array of doubles) for which ``predicate`` (an LLVM
    comparison of each with ``v``) holds, as the bits of an integer (lane 0 the lowest)."""
    ordered, operator = predicate

    @intrinsic
    def compared(typingctx, x, start, v):
        def codegen(context, builder, signature, args):
            quad = builder.load(_quad_pointer(context, builder, signature.args[0], args[0], args[1]), align=8)
            value = builder.insert_element(ir.Constant(_QUAD, ir.Undefined), args[2], ir.Constant(_INT, 0))
            value = builder.shuffle_vector(value, value, ir.Constant(ir.VectorType(_INT, 4), [0] * 4))
            compare = builder.fcmp_ordered if ordered else builder.fcmp_unordered
            bits = builder.bitcast(compare(operator, quad, value), ir.IntType(4))
            return builder.zext(bits, ir.IntType(64))
        return types.int64(_doubles(x), types.intp, types.float64), codegen
    return compared


_over = _lanes_compared((False, ">"))  # not (x <= v): larger, or NaN
_larger = _lanes_compared((True, ">"))
_equal = _lanes_compared((True, "=="))


@intrinsic
def _jumps_of(typingctx, ahead, power, behind, width):
    """:func:`jump_profile`'s jump in each lane from the running power ``width`` samples ahead, at the sample and
    ``4 width`` behind: ``sqrt(after / max(before, 1e-300 + after * 1e-12))``."""
    def codegen(context, builder, signature, args):
        ahead, power, behind, width = args
        def broadcast(value):
            quad = builder.insert_element(ir.Constant(_QUAD, ir.Undefined), value, ir.Constant(_INT, 0))
            return builder.shuffle_vector(quad, quad, ir.Constant(ir.VectorType(_INT, 4), [0] * 4))
        after = builder.fdiv(builder.fsub(ahead, power), broadcast(builder.sitofp(width, ir.DoubleType())))
        before = builder.fdiv(builder.fsub(power, behind),
                              broadcast(builder.sitofp(builder.mul(width, ir.Constant(width.type, 4)), ir.DoubleType())))
        floor = builder.fadd(broadcast(ir.Constant(ir.DoubleType(), 1e-300)),
                             builder.fmul(after, broadcast(ir.Constant(ir.DoubleType(), 1e-12))))
        larger = builder.select(builder.fcmp_ordered("<", before, floor), floor, before)
        sqrt = cgutils.get_or_insert_function(builder.module, ir.FunctionType(_QUAD, [_QUAD]), "llvm.sqrt.v4f64")
        return builder.call(sqrt, [builder.fdiv(after, larger)])
    return _quad_type(_quad_type, _quad_type, _quad_type, types.intp), codegen


@jit
def high_pass(sos, x):
    """``scipy.signal.sosfilt(sos, x)`` for one second-order section (the same operations), its largest magnitude
    (``np.max(np.abs(..), initial=0.0)``) and where it first is (0 if none), in one pass: the filter waits on its
    recursion, the largest is found meanwhile."""
    b0, b1, b2, a1, a2 = sos[0, 0], sos[0, 1], sos[0, 2], sos[0, 4], sos[0, 5]
    z0 = z1 = 0.0
    peak = 0.0
    at = 0
    out = np.empty(len(x))
    for i in range(len(x)):
        v = x[i]
        y = b0 * v + z0
        z0 = b1 * v - a1 * y + z1
        z1 = b2 * v - a2 * y
        out[i] = y
        if abs(y) > peak:
            at = i
        peak = max(peak, abs(y))
    return out, peak, at


@jit
def frame_energies(x, starts, window):
    """The energy over the bins of ``numpy.fft.rfft`` of each frame ``x[s:s + len(window)] * window`` (``s`` in
    ``starts``), by Parseval's theorem: the half spectrum counts its first and last bins once. Each sum (of the
    squares, of the even and of the odd samples) is added in four lanes (every fourth sample; those left over, even or
    odd, in the first two), the lanes summed at the end; the four lanes as one vector's, two frames side by side."""
    out = np.empty(len(starts))
    for i in range(0, len(starts) - 1, 2):
        out[i], out[i + 1] = _two_energies(x, starts[i], starts[i + 1], window)
    if len(starts) % 2:
        out[-1] = _two_energies(x, starts[-1], starts[-1], window)[0]
    return out


@jit(inline="always")
def _two_energies(x, first, second, window):
    """The energies of the frames from ``first`` and ``second`` (:func:`frame_energies`')."""
    size = len(window)
    zero = _quad(0.0)
    power, total, power_other, total_other = zero, zero, zero, zero
    j = 0
    while j + 4 <= size:
        w = _load(window, j)
        v, u = _times(_load(x, first + j), w), _times(_load(x, second + j), w)
        power, power_other = _plus_times(power, v, v), _plus_times(power_other, u, u)
        total, total_other = _plus(total, v), _plus(total_other, u)
        j += 4
    return (_energy(x, first, window, j, power, total, size),
            _energy(x, second, window, j, power_other, total_other, size))


@jit(inline="always")
def _energy(x, start, window, j, power, total, size):
    """A frame's energy from its lanes' sums up to sample ``j`` (the samples left over: even ones in the first lane, odd
    ones in the second)."""
    p0, p1, p2, p3 = _lane4(power, 0), _lane4(power, 1), _lane4(power, 2), _lane4(power, 3)
    t0, t1, t2, t3 = _lane4(total, 0), _lane4(total, 1), _lane4(total, 2), _lane4(total, 3)
    while j < size:
        v0 = x[start + j] * window[j]
        if j % 2 == 0:
            p0, t0 = p0 + v0 * v0, t0 + v0
        else:
            p1, t1 = p1 + v0 * v0, t1 + v0
        j += 1
    power, even, odd = (p0 + p2) + (p1 + p3), t0 + t2, t1 + t3
    return (size * power + (even + odd) ** 2 + (even - odd) ** 2) / 2.0


@jit
def _column(sos, other, k):
    """Column ``k`` of the two filters' sections as lanes (``sos``'s four, then ``other``'s)."""
    return _lanes((sos[0, k], sos[1, k], sos[2, k], sos[3, k], other[0, k], other[1, k], other[2, k], other[3, k]))


@jit(inline="always")
def _sections(sos, other, third):
    """The numerators and denominators of :func:`low_pass_three`'s filters as lanes: ``sos``'s and ``other``'s
    sections in one vector's, ``third``'s in another's (twice: its lanes four to seven idle)."""
    return ((_column(sos, other, 0), _column(sos, other, 1), _column(sos, other, 2), _column(sos, other, 4),
             _column(sos, other, 5)),
            (_column(third, third, 0), _column(third, third, 1), _column(third, third, 2), _column(third, third, 4),
             _column(third, third, 5)))


@jit(inline="always")
def _started(state, step):
    """The lanes of ``state`` (outputs, states) of the sections after ``step`` set to 0: those not yet at the signal's
    first sample keep their zero states (as sosfilt's do)."""
    return _zeroed(state[0], step), _zeroed(state[1], step), _zeroed(state[2], step)


@jit(inline="always")
def _filtered(v, y, z0, z1, sections):
    """One step of the sections' lanes on input ``v`` (the previous outputs ``y``, states ``z0``, ``z1``): the outputs
    and states after."""
    b0, b1, b2, a1, a2 = sections
    return _biquads(_shifted_in(y, v), b0, b1, b2, a1, a2, z0, z1)


@jit
def low_pass_three(sos, q, other, q_other, third, q_third, x):
    """``scipy.signal.sosfilt(f, x)[::q_f]`` for three filters ``f`` of 4 second-order sections each (8th order): the
    same operations, the first two filters' eight sections as one vector's lanes, the third's as another's (the two
    vectors' recursions run side by side: the third costs little)."""
    sections, sections_third = _sections(sos, other, third)
    y = z0 = z1 = w = u0 = u1 = _lanes((0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
    n = len(x)
    out = np.empty((n + q - 1) // q)
    out_other = np.empty((n + q_other - 1) // q_other)
    out_third = np.empty((n + q_third - 1) // q_third)
    for i in range(3):
        v = x[i] if i < n else 0.0
        y, z0, z1 = _started(_filtered(v, y, z0, z1, sections), i)
        w, u0, u1 = _started(_filtered(v, w, u0, u1, sections_third), i)
    skip, skip_other, skip_third = 0, 0, 0
    for i in range(3, n + 3):  # the last section's output at step i is sample i - 3's
        v = x[i] if i < n else 0.0
        y, z0, z1 = _filtered(v, y, z0, z1, sections)
        w, u0, u1 = _filtered(v, w, u0, u1, sections_third)
        if skip == 0:  # the outputs each filter keeps (every q-th): written out (not in a helper: 10 times slower)
            out[(i - 3) // q] = _lane(y, 3)
            skip = q
        skip -= 1
        if skip_other == 0:
            out_other[(i - 3) // q_other] = _lane(y, 7)
            skip_other = q_other
        skip_other -= 1
        if skip_third == 0:
            out_third[(i - 3) // q_third] = _lane(w, 3)
            skip_third = q_third
        skip_third -= 1
    return out, out_other, out_third


@jit(error_model="numpy")
def low_pass_three_and_jumps(sos, q, other, q_other, third, q_third, x, rise, width):
    """:func:`low_pass_three` of ``x`` and :func:`jump_profile` of ``rise`` (as long as ``x``) over ``width``
    samples, in one loop: the filters wait on their recursions, the jumps on the divider, the running power on its
    additions; side by side each is done while the others wait. The same operations as each alone, the same bits.

    Returns the three decimated signals and the jump profile."""
    sections, sections_third = _sections(sos, other, third)
    y = z0 = z1 = w = u0 = u1 = _lanes((0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
    n = len(x)
    out = np.empty((n + q - 1) // q)
    out_other = np.empty((n + q_other - 1) // q_other)
    out_third = np.empty((n + q_third - 1) // q_third)
    jump = np.empty(n)
    jump[:4 * width] = 0.0  # the rest written below
    ring, size = _ring(width)
    running, done = 0.0, 1
    for i in range(3):
        v = x[i] if i < n else 0.0
        y, z0, z1 = _started(_filtered(v, y, z0, z1, sections), i)
        w, u0, u1 = _started(_filtered(v, w, u0, u1, sections_third), i)
    skip, skip_other, skip_third, i = 0, 0, 0, 3
    while i < n + 3:  # the last section's output at step i is sample i - 3's
        steps = 1
        # four jumps, and four steps, at a time from the first jump on while the jumps' windows and the power added
        # ahead are within the signal
        if i >= 4 * width and i + 4 + _AHEAD <= n - width:
            if done == 1:
                running, done = _powers(ring, size, rise, running, done, i + width + _AHEAD - 1)
            for j in range(i + width + _AHEAD, i + width + _AHEAD + 4):
                running = running + rise[j - 1] * rise[j - 1]
                ring[j & (size - 1)] = ring[(j & (size - 1)) + size] = running
            done = i + width + _AHEAD + 4
            _store(jump, i, _jumps_of(_load(ring, (i + width) & (size - 1)), _load(ring, i & (size - 1)),
                                      _load(ring, (i - 4 * width) & (size - 1)), width))
            steps = 4
        for k in range(i, i + steps):
            v = x[k] if k < n else 0.0
            y, z0, z1 = _filtered(v, y, z0, z1, sections)
            w, u0, u1 = _filtered(v, w, u0, u1, sections_third)
            if skip == 0:  # the outputs each filter keeps (every q-th): written out (not in a helper: 10 times slower)
                out[(k - 3) // q] = _lane(y, 3)
                skip = q
            skip -= 1
            if skip_other == 0:
                out_other[(k - 3) // q_other] = _lane(y, 7)
                skip_other = q_other
            skip_other -= 1
            if skip_third == 0:
                out_third[(k - 3) // q_third] = _lane(w, 3)
                skip_third = q_third
            skip_third -= 1
        i += steps
    _last_jumps(jump, ring, size, rise, running, done, max(done - width - _AHEAD, 4 * width), width)
    return out, out_other, out_third, jump


@jit(inline="always")
def _powers(ring, size, x, running, done, upto):
    """The running power of ``x`` (its squares added in order) up to ``p[upto]`` in ``ring`` (``p[j]`` at ``j % size``
    and at ``size`` after: four in a row may be read from any slot); returns the sum and the next ``j`` to add."""
    while done <= upto:
        running = running + x[done - 1] * x[done - 1]
        ring[done & (size - 1)] = ring[(done & (size - 1)) + size] = running
        done += 1
    return running, done


@jit(inline="always")
def _ring(width):
    """A ring of the running power (:func:`_powers`) for jumps over ``width`` samples: ``p[0]`` = 0 in it, its size."""
    size = 1
    while size < 5 * width + 4 + _AHEAD:  # the running power from 4 widths before the samples to a width and 4 after
        size *= 2
    ring = np.empty(2 * size)
    ring[0] = ring[size] = 0.0
    return ring, size


@jit(inline="always")
def _last_jumps(jump, ring, size, x, running, done, first, width):
    """The jumps of ``x`` from ``first`` to its end, one at a time (their windows cut at the signal's end), from the
    running power so far in ``ring``."""
    n = len(x)
    for k in range(first, n):
        running, done = _powers(ring, size, x, running, done, min(k + width, n))
        after = (ring[min(k + width, n) & (size - 1)] - ring[k & (size - 1)]) / width
        before = (ring[k & (size - 1)] - ring[max(k - 4 * width, 0) & (size - 1)]) / (4 * width)
        jump[k] = np.sqrt(after / max(before, 1e-300 + after * 1e-12))


@jit(error_model="numpy")
def jump_profile(x, width):
    """The RMS jump of ``x`` at each sample (:func:`.onsets._windows`' next ``width`` samples over the ``4 width``
    before, the power summed in order from ``x[0]``), 0 over the first ``4 width``: four jumps as one vector's lanes
    while the running power is added ahead, in a ring of the samples the windows span (not the recording's length)."""
    n = len(x)
    jump = np.empty(n)
    jump[:4 * width] = 0.0  # the rest written below
    ring, size = _ring(width)
    running, done = 0.0, 1
    i = 4 * width
    if i + 4 + _AHEAD <= n - width:
        running, done = _powers(ring, size, x, running, done, i + width + _AHEAD - 1)
        while i + 4 + _AHEAD <= n - width:
            for j in range(i + width + _AHEAD, i + width + _AHEAD + 4):
                running = running + x[j - 1] * x[j - 1]
                ring[j & (size - 1)] = ring[(j & (size - 1)) + size] = running
            _store(jump, i, _jumps_of(_load(ring, (i + width) & (size - 1)), _load(ring, i & (size - 1)),
                                      _load(ring, (i - 4 * width) & (size - 1)), width))
            i += 4
        done = i + width + _AHEAD
    _last_jumps(jump, ring, size, x, running, done, i, width)
    return jump


@jit
def peak_pick_over(x, gap, below):
    """:func:`.onsets._peak_pick`'s peaks (``librosa.util.peak_pick(x, pre_max=gap, post_max=gap, pre_avg=1,
    post_avg=1, delta=0, wait=gap)``, in linear time) over ``below`` (the largest float under the least asked: those at
    least that, and NaN; ``-inf``: every peak), the stretches under it skipped where what is picked after them does not
    depend on what is picked in them.

    A sample is a peak when it is the largest from ``gap`` before it to ``gap - 1`` after, at least its predecessor's
    and their mean, and more than ``gap`` after the last peak (greedily). From each sample, the first larger one after
    it within its window is sought four samples a comparison: there is none there (each between is no larger than it,
    the larger one in its window); else it is the largest after it, and those after it up to its window's end are
    smaller (it is in their window: none) or equal (tried in turn, what is known of the equal run kept: how far after
    it all are no larger, the nearest larger before it).

    A peak keeps those after it from being picked for ``gap`` samples only: where no sample from ``q - gap`` to
    ``q`` is a peak (the largest of its window, at least its predecessor's and their mean), those from ``q`` on are
    picked as though the signal began there (the last picked before is more than ``gap`` samples before each).
    Before the next sample over ``below``, ``q`` is sought ``gap`` samples back at a time, the picking started there;
    where none is found after where it stands, it goes on through the stretch."""
    count = len(x)
    none = -count - gap - 1
    first = True
    for n in range(min(gap, count)):
        if x[n] > x[0]:
            first = False
    kept = np.empty(count // (gap + 1) + 2, dtype=np.int64)
    found, last = 0, -gap - 1
    if first:
        last = 0
        if not x[0] <= below:
            kept[0], found = 0, 1
    n, tie, scanned, bigger = 1, False, 0, none
    while n < count:
        if not tie and x[n] <= below:
            h = _first_over_far(x, n, count, below)
            if h == count:
                break
            q = h - gap
            while q - gap > n and _any_peak(x, q - gap, q, gap):
                q -= gap
            if q - gap > n:  # no peak from q - gap to q: what was picked before does not matter from q on
                n, last = q, -gap - 1
        v = x[n]
        high = min(count, n + gap)
        m = _first_over(x, max(scanned, n + 1) if tie else n + 1, high, v)
        if m < high:
            n, tie = m, False
            continue
        if not tie:
            bigger = _last_larger(x, max(0, n - gap), n, v, none)
        if bigger < n - gap and v >= (x[n - 1] + v) / 2.0 and n > last + gap:
            if not v <= below:
                kept[found] = n
                found += 1
            last = n
        scanned = high
        m = _first_equal(x, n + 1, high, v)
        n, tie = m, m < high
    return kept[:found].copy()


@jit(inline="always")
def _first_over_far(x, low, high, v):
    """:func:`_first_over` for a long way: sixteen samples a step (four comparisons of four), then four."""
    m = low
    while m + 16 <= high and (_over(x, m, v) | _over(x, m + 4, v) | _over(x, m + 8, v) | _over(x, m + 12, v)) == 0:
        m += 16
    return _first_over(x, m, high, v)


@jit(inline="always")
def _any_peak(x, low, high, gap):
    """Whether a sample from ``low`` (≥ 1) to ``high`` is the largest of its window (from ``gap`` samples before it to
    ``gap - 1`` after) and at least its predecessor's and their mean: :func:`.onsets._peak_pick`'s test but the last peak's."""
    count = len(x)
    n = low
    while n < high:
        v = x[n]
        end = min(count, n + gap)
        m = _first_over(x, n + 1, end, v)
        if m < end:  # those before m are under it, or as large with m after them
            n = m
            continue
        if _last_larger(x, max(0, n - gap), n, v, -count - gap - 1) < n - gap and v >= (x[n - 1] + v) / 2.0:
            return True
        n = _first_equal(x, n + 1, end, v)  # those before it are under v, n in their window
    return False


@jit(inline="always")
def _first_over(x, low, high, v):
    """The first ``m`` from ``low`` with ``not x[m] <= v`` before ``high``, else ``high`` (four samples a comparison)."""
    m = low
    while m + 4 <= high and _over(x, m, v) == 0:
        m += 4
    while m < high and x[m] <= v:
        m += 1
    return m


@jit(inline="always")
def _first_equal(x, low, high, v):
    """The first ``m`` from ``low`` with ``x[m] == v`` before ``high``, else ``high``."""
    m = low
    while m + 4 <= high and _equal(x, m, v) == 0:
        m += 4
    while m < high and x[m] != v:
        m += 1
    return m


@jit(inline="always")
def _last_larger(x, low, high, v, none):
    """The last ``j`` before ``high`` with ``x[j] > v`` from ``low``, else ``none``."""
    j = high
    while j - 4 >= low and _larger(x, j - 4, v) == 0:
        j -= 4
    while j > low:
        j -= 1
        if x[j] > v:
            return j
    return none


@jit
def burg(y, order):
    """``librosa.lpc(y, order=order)`` for a 1-D ``y`` (Burg's method, as Marple): the same operations, except that
    each sum of products is added in four lanes (every fourth term; those left over in the first), the lanes summed at
    the end (the same to rounding: one chain of additions a sample made the method wait on each addition). Each
    order's update of the prediction errors (in place) and the next order's numerator are one pass, four samples
    as one vector's lanes."""
    tiny = np.finfo(np.float64).tiny
    n = len(y)
    f = y[1:].copy()  # f[i:] is the forward error at order i, b[:n - 1 - i] the backward one
    b = y[:-1].copy()
    a = np.zeros(order + 1)
    a_prev = np.zeros(order + 1)
    a[0] = a_prev[0] = 1.0
    den = _lanes_dot(f, f, n - 1) + _lanes_dot(b, b, n - 1)
    dot = _lanes_dot(b, f, n - 1)
    for i in range(order):
        m = n - 1 - i  # the errors' length at this order
        reflect = dot * -2
        reflect /= den + tiny
        a_prev, a = a, a_prev
        for j in range(1, i + 2):
            a[j] = a_prev[j] + reflect * a_prev[i - j + 1]
        dot = _updated_dot(f, i, b, m, reflect)
        q = 1.0 - reflect ** 2
        den = q * den - b[m - 1] ** 2 - f[i] ** 2
    return a


@jit(inline="always")
def _lanes_dot(x, y, n):
    """``x[:n] @ y[:n]`` added in four lanes (every fourth term; those left over in the first), summed at the end."""
    s0 = s1 = s2 = s3 = 0.0
    k = 0
    while k + 4 <= n:
        s0 += x[k] * y[k]
        s1 += x[k + 1] * y[k + 1]
        s2 += x[k + 2] * y[k + 2]
        s3 += x[k + 3] * y[k + 3]
        k += 4
    while k < n:
        s0 += x[k] * y[k]
        k += 1
    return (s0 + s1) + (s2 + s3)


@jit(inline="always")
def _updated_dot(f, i, b, m, reflect):
    """One order of Burg's method: the errors ``f[i:i + m]`` and ``b[:m]`` updated in place by ``reflect``, and the next
    order's numerator, ``b[:m - 1] @ f[i + 1:i + m]`` in four lanes (:func:`_lanes_dot`), each product added as
    soon as both its errors are updated (four samples at a time, as one vector's lanes)."""
    old = f[i]
    f[i] = old + reflect * b[0]
    b[0] = b[0] + reflect * old
    r = _quad(reflect)
    sums = _quad(0.0)
    last = _quad(b[0])  # its last lane: the updated backward error before the block's
    j = 0  # the numerator's products: b[j] * f[i + j + 1]
    while j + 4 <= m - 1:
        forward, backward = _load(f, i + j + 1), _load(b, j + 1)
        forward, backward = _plus_times(forward, r, backward), _plus_times(backward, r, forward)
        _store(f, i + j + 1, forward)
        _store(b, j + 1, backward)
        sums = _plus_times(sums, _after(last, backward), forward)
        last = backward
        j += 4
    while j < m - 1:  # the last products (all in the first lane, as lanes_dot adds them)
        old = f[i + j + 1]
        f[i + j + 1] = old + reflect * b[j + 1]
        b[j + 1] = b[j + 1] + reflect * old
        sums = _first_lane_plus(sums, b[j] * f[i + j + 1])
        j += 1
    return _sum_of_lanes(sums)


@jit
def prediction_error(a, x):
    """:func:`._kernels.prediction_error` (``scipy.signal.lfilter(a, [1.0], x)``: ``x`` through the FIR ``a``, each
    output's taps added from the first): the same operations, 32 outputs at a time as eight vectors held over all
    the taps."""
    n, taps = len(x), len(a)
    out = np.empty(n)
    head = min(n, taps - 1)  # the outputs with fewer taps than a's (the signal starts from nothing)
    for j in range(head):
        total = a[0] * x[j]
        for k in range(1, j + 1):
            total += a[k] * x[j - k]
        out[j] = total
    j = head
    while j + 32 <= n:
        tap = _quad(a[0])
        s0, s1, s2, s3 = (_times(tap, _load(x, j)), _times(tap, _load(x, j + 4)), _times(tap, _load(x, j + 8)),
                          _times(tap, _load(x, j + 12)))
        s4, s5, s6, s7 = (_times(tap, _load(x, j + 16)), _times(tap, _load(x, j + 20)), _times(tap, _load(x, j + 24)),
                          _times(tap, _load(x, j + 28)))
        for k in range(1, taps):
            tap = _quad(a[k])
            s0, s1 = _plus_times(s0, tap, _load(x, j - k)), _plus_times(s1, tap, _load(x, j + 4 - k))
            s2, s3 = _plus_times(s2, tap, _load(x, j + 8 - k)), _plus_times(s3, tap, _load(x, j + 12 - k))
            s4, s5 = _plus_times(s4, tap, _load(x, j + 16 - k)), _plus_times(s5, tap, _load(x, j + 20 - k))
            s6, s7 = _plus_times(s6, tap, _load(x, j + 24 - k)), _plus_times(s7, tap, _load(x, j + 28 - k))
        for i, sums in enumerate((s0, s1, s2, s3, s4, s5, s6, s7)):
            _store(out, j + 4 * i, sums)
        j += 32
    for t in range(j, n):
        total = a[0] * x[t]
        for k in range(1, taps):
            total += a[k] * x[t - k]
        out[t] = total
    return out
