"""Compiled loops of the onset detector's modes' band and level band (:mod:`.onsets`' steps 4 and 5).

Each computes what the numpy or BLAS code it replaced did, to the bit: a product BLAS ran is run
here as OpenBLAS's kernel runs it (each entry's fused multiply-adds in row order), so that the
least-squares fits downstream see the same normal equations.
"""

import numpy as np
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

from .._jit import jit

_VECTOR = ir.VectorType(ir.DoubleType(), 4)  # four doubles: AVX's registers


def _contiguous(*arrays):
    """Whether each of the numba types ``arrays`` is a C-contiguous array (the intrinsics' loads read neighbours)."""
    return all(isinstance(array, types.Array) and array.layout == "C" for array in arrays)


def _load_vector(builder, data, index, vector=_VECTOR):
    """The doubles from ``data[index]`` (a pointer to double; no alignment assumed) as a ``vector``."""
    return builder.load(builder.bitcast(builder.gep(data, [index]), vector.as_pointer()), align=8)


def _broadcast(builder, value, vector=_VECTOR):
    """The double ``value`` in each lane of a ``vector``."""
    lanes = builder.insert_element(ir.Constant(vector, ir.Undefined), value, ir.Constant(ir.IntType(32), 0))
    return builder.shuffle_vector(lanes, ir.Constant(vector, ir.Undefined),
                                  ir.Constant(ir.VectorType(ir.IntType(32), vector.count), [0] * vector.count))


def _largest_in(magnitude):
    """An intrinsic ``(x, low, blocks)``: the largest of 0.0 and ``x[low:low + 16 * blocks]`` (their magnitudes, with
    ``magnitude``), as ``peak = max(peak, v)`` from ``peak = 0.0`` gives it: each of 16 lanes (four vectors) keeps its
    own ``max`` (numba's: ``v`` where ``v > peak``, NaN never taken), the lanes' largest taken at the end; the largest
    of a set is the same in any order (the magnitudes hold no -0.0 to tie with 0.0)."""

    @intrinsic
    def largest(typingctx, x, low, blocks):
        if not _contiguous(x):
            return None
        sig = types.float64(x, low, blocks)

        def codegen(context, builder, signature, args):
            data = context.make_array(signature.args[0])(context, builder, args[0]).data
            low, blocks = (context.cast(builder, args[n], signature.args[n], types.intp) for n in (1, 2))
            fabs = cgutils.get_or_insert_function(builder.module, ir.FunctionType(_VECTOR, [_VECTOR]), "llvm.fabs.v4f64")
            peaks = [cgutils.alloca_once_value(builder, ir.Constant(_VECTOR, [0.0] * 4)) for _ in range(4)]
            with cgutils.for_range(builder, blocks) as loop:
                first = builder.add(low, builder.mul(loop.index, ir.Constant(low.type, 16)))
                for g, peak in enumerate(peaks):
                    v = _load_vector(builder, data, builder.add(first, ir.Constant(low.type, 4 * g)))
                    v = builder.call(fabs, [v]) if magnitude else v
                    so_far = builder.load(peak)
                    builder.store(builder.select(builder.fcmp_ordered(">", v, so_far), v, so_far), peak)
            best = ir.Constant(ir.DoubleType(), 0.0)
            for peak in peaks:
                lanes = builder.load(peak)
                for k in range(4):
                    v = builder.extract_element(lanes, ir.Constant(ir.IntType(32), k))
                    best = builder.select(builder.fcmp_ordered(">", v, best), v, best)
            return best

        return sig, codegen

    return largest


largest_of = _largest_in(False)
largest_magnitude_of = _largest_in(True)


def _gram_tile(height, lanes, vectors=1):
    """An intrinsic ``tile(rows, width, count, i, j, gram)``: ``gram[i:i + height, j:j + columns] += rows[:count, i:i +
    height].T @ rows[:count, j:j + columns]`` (both C-contiguous, ``width`` columns; ``columns``: ``vectors`` vectors
    of ``lanes``), each entry's products added by fused multiply-adds in row order from 0, as OpenBLAS's kernel adds
    them; the sums in vector registers (numba vectorises no loop whose sums must stay in order)."""
    vector = ir.VectorType(ir.DoubleType(), lanes)

    @intrinsic
    def tile(typingctx, rows, width, count, i, j, gram):
        if not _contiguous(rows, gram):
            return None
        sig = types.none(rows, width, count, i, j, gram)

        def codegen(context, builder, signature, args):
            rows_data = context.make_array(signature.args[0])(context, builder, args[0]).data
            gram_data = context.make_array(signature.args[5])(context, builder, args[5]).data
            width, count, i, j = (context.cast(builder, value, kind, types.intp)
                                  for value, kind in zip(args[1:5], signature.args[1:5]))
            fma = cgutils.get_or_insert_function(builder.module, ir.FunctionType(vector, [vector] * 3),
                                                 f"llvm.fma.v{lanes}f64")
            sums = [[cgutils.alloca_once_value(builder, ir.Constant(vector, [0.0] * lanes)) for _ in range(vectors)]
                    for _ in range(height)]

            with cgutils.for_range(builder, count) as loop:
                row = builder.mul(loop.index, width)
                left = builder.add(row, i)
                right = builder.add(row, j)
                b = [_load_vector(builder, rows_data, builder.add(right, ir.Constant(j.type, lanes * h)), vector)
                     for h in range(vectors)]
                for k in range(height):
                    a = builder.load(builder.gep(rows_data, [builder.add(left, ir.Constant(i.type, k))]))
                    a = _broadcast(builder, a, vector)
                    for h in range(vectors):
                        builder.store(builder.call(fma, [a, b[h], builder.load(sums[k][h])]), sums[k][h])
            for k in range(height):
                row = builder.add(builder.mul(builder.add(i, ir.Constant(i.type, k)), width), j)
                for h in range(vectors):
                    at = builder.gep(gram_data, [builder.add(row, ir.Constant(j.type, lanes * h))])
                    pointer = builder.bitcast(at, vector.as_pointer())
                    builder.store(builder.fadd(builder.load(pointer, align=8), builder.load(sums[k][h])), pointer,
                                  align=8)
            return context.get_dummy_value()

        return sig, codegen

    return tile


def _wide_vectors():
    """Whether the compiled code may use AVX-512's 32 registers of 8 doubles (numba's target: this processor, or the
    one its settings name)."""
    from llvmlite import binding
    from numba.core import config

    return "+avx512f" in (config.CPU_FEATURES or binding.get_host_cpu_features().flatten())


# the normal equations' tile: 16 sums of 8 lanes with AVX-512, 8 of 4 with AVX (more would spill from the registers)
_TILE_ROWS, _TILE_COLUMNS = (8, 16) if _wide_vectors() else (4, 8)
_GRAM_TILE = _gram_tile(_TILE_ROWS, _TILE_COLUMNS // 2, 2)
_GRAM_HALF_TILE = _gram_tile(_TILE_ROWS, _TILE_COLUMNS // 2)  # a strip's last columns, half a tile's or fewer
_STRIP = 3 * _TILE_COLUMNS  # a column past the tiles: its sums with this many rows at a time, six vectors' lanes
_GRAM_STRIP = _gram_tile(1, _TILE_COLUMNS // 2, 6)


@jit
def weighted_gram(x, weight, order, block):
    """The normal equations ``Σ r r^T`` of the rows ``r = (x[n], x[n - 1], …, x[n - order]) weight[n]`` for ``n`` from
    ``order`` to ``len(x) - 1`` [shape=(order + 1, order + 1)].

    What numpy gave: each ``block`` of rows' product ``rows.T @ rows`` (OpenBLAS's) added to the sum in turn. The
    rows are formed (each product rounded) a block at a time, and only the upper triangle's products are taken (the
    lower's are the same: a fused multiply-add's two factors commute): in tiles over the first whole tiles' rows and
    columns, and the columns past them (the last of order 40's 41, 24's 25) each a strip of their own, their sums
    with every row before them, not in a tile's rows (mostly past the triangle).
    """
    size = order + 1
    square = size - size % _TILE_ROWS  # the columns the tiles cover
    # whole tiles from the diagonal on, whole strips from column 0: the padding's columns stay 0 and their sums are
    # not read
    width = max(size + max(_TILE_ROWS, _TILE_COLUMNS) - 1, -(-size // _STRIP) * _STRIP)
    rows = np.zeros((block, width))
    total = np.zeros((width, width))
    backwards = x[::-1].copy()  # a row's samples in a row: x[n - k] at len(x) - 1 - n + k
    for start in range(order, len(x), block):
        count = min(len(x), start + block) - start
        for n in range(start, start + count):
            row, scale, lagged = rows[n - start], weight[n], backwards[len(x) - 1 - n:len(x) - 1 - n + size]
            for k in range(size):
                row[k] = lagged[k] * scale
        for i in range(0, square, _TILE_ROWS):
            for j in range(i, square, _TILE_COLUMNS):
                if square - j > _TILE_COLUMNS // 2:
                    _GRAM_TILE(rows, width, count, i, j, total)
                else:
                    _GRAM_HALF_TILE(rows, width, count, i, j, total)
        for k in range(square, size):  # column k's sums with rows 0 to k, in total's row k
            for j in range(0, k + 1, _STRIP):
                _GRAM_STRIP(rows, width, count, k, j, total)
    gram = np.empty((size, size))
    for i in range(size):
        for j in range(i, size):
            gram[i, j] = gram[j, i] = total[i, j] if j < square else total[j, i]
    return gram


@intrinsic
def _five_window_sums(typingctx, x, first, t0, t1, size, out):
    """The five windows of ``size`` samples of ``x`` from ``first`` to ``first + 4``: each one's products with ``t0`` and
    with ``t1`` summed in order (:func:`._kernels.window_dot`), and its squares summed in
    :func:`._kernels.pair_dot`'s order, into ``out[0:5]``, ``out[5:10]`` and ``out[10:15]``.

    The windows side by side in vector lanes (the first four, and the last four: the fifth), each lane's
    operations those of its own chain of additions.
    """
    if not _contiguous(x, t0, t1, out):
        return None
    sig = types.none(x, first, t0, t1, size, out)

    def codegen(context, builder, signature, args):
        x_data, t0_data, t1_data, out_data = (context.make_array(signature.args[n])(context, builder, args[n]).data
                                              for n in (0, 2, 3, 5))
        first, size = (context.cast(builder, args[n], signature.args[n], types.intp) for n in (1, 4))

        def constant(n):
            return ir.Constant(first.type, n)

        zero = ir.Constant(_VECTOR, [0.0] * 4)
        dots0, dots1, even, odd = ([cgutils.alloca_once_value(builder, zero) for _ in range(2)] for _ in range(4))

        def windows(j):  # x from j in the first four windows and in the last four
            at = builder.add(first, j)
            return [_load_vector(builder, x_data, builder.add(at, constant(k))) for k in (0, 1)]

        def add_to(sums, values, scale=None):
            for total, value in zip(sums, values):
                builder.store(builder.fadd(builder.load(total), builder.fmul(value, value if scale is None else scale)),
                              total)

        def dot_step(j):
            values = windows(j)
            add_to(dots0, values, _broadcast(builder, builder.load(builder.gep(t0_data, [j]))))
            add_to(dots1, values, _broadcast(builder, builder.load(builder.gep(t1_data, [j]))))

        blocks = builder.sdiv(size, constant(8))
        with cgutils.for_range(builder, blocks) as loop:
            j = builder.mul(loop.index, constant(8))
            for step in range(8):
                dot_step(builder.add(j, constant(step)))
            for step in (6, 4, 2, 0):  # pair_dot's order: the vector's last pair first, into the lanes
                add_to(even, windows(builder.add(j, constant(step))))
                add_to(odd, windows(builder.add(j, constant(step + 1))))
        start = builder.mul(blocks, constant(8))
        with cgutils.for_range(builder, builder.sub(size, start)) as loop:
            dot_step(builder.add(start, loop.index))
        pairs = builder.sdiv(builder.add(builder.sub(size, start), constant(1)), constant(2))
        with cgutils.for_range(builder, pairs) as loop:
            j = builder.add(start, builder.mul(loop.index, constant(2)))
            add_to(even, windows(j))
            with builder.if_then(builder.icmp_signed("<", builder.add(j, constant(1)), size)):
                add_to(odd, windows(builder.add(j, constant(1))))

        def store(offset, sums):  # sums: the four windows' and the last four's values
            low, high = sums
            for k in range(5):
                lane = builder.extract_element(low if k < 4 else high, ir.Constant(ir.IntType(32), min(k, 3)))
                builder.store(lane, builder.gep(out_data, [constant(offset + k)]))

        store(0, [builder.load(total) for total in dots0])
        store(5, [builder.load(total) for total in dots1])
        store(10, [builder.fadd(builder.load(e), builder.load(o)) for e, o in zip(even, odd)])
        return context.get_dummy_value()

    return sig, codegen


@jit
def five_window_sums(x, first, t0, t1, size, out):
    """:func:`_five_window_sums` (``x[first + 4 + size - 1]`` and ``t0[size - 1]``, ``t1[size - 1]`` must exist)."""
    _five_window_sums(x, first, t0, t1, size, out)


_LAGS = 8  # lags side by side: one AVX-512 register, or two AVX ones (two chains of additions in turn)
_LAG_VECTOR = ir.VectorType(ir.DoubleType(), _LAGS)


@intrinsic
def _lag_dots(typingctx, y, basis, lag, steps, out):
    """The first ``steps`` products of ``y`` from ``lag + l`` (for the :data:`_LAGS` lanes ``l``) with each of
    ``basis``'s two columns (C-contiguous, shape (m, 2)), each lane's added in order from 0, into ``out[:_LAGS]`` and
    ``out[_LAGS:]``."""
    if not _contiguous(y, basis, out):
        return None
    sig = types.none(y, basis, lag, steps, out)

    def codegen(context, builder, signature, args):
        y_data, basis_data, out_data = (context.make_array(signature.args[n])(context, builder, args[n]).data
                                        for n in (0, 1, 4))
        lag, steps = (context.cast(builder, args[n], signature.args[n], types.intp) for n in (2, 3))
        sums = [cgutils.alloca_once_value(builder, ir.Constant(_LAG_VECTOR, [0.0] * _LAGS)) for _ in range(2)]
        with cgutils.for_range(builder, steps) as loop:
            values = _load_vector(builder, y_data, builder.add(lag, loop.index), _LAG_VECTOR)
            row = builder.mul(loop.index, ir.Constant(lag.type, 2))
            for q in range(2):
                scale = builder.load(builder.gep(basis_data, [builder.add(row, ir.Constant(lag.type, q))]))
                scale = _broadcast(builder, scale, _LAG_VECTOR)
                builder.store(builder.fadd(builder.load(sums[q]), builder.fmul(values, scale)), sums[q])
        for q in range(2):
            total = builder.load(sums[q])
            for lane in range(_LAGS):
                builder.store(builder.extract_element(total, ir.Constant(ir.IntType(32), lane)),
                              builder.gep(out_data, [ir.Constant(lag.type, _LAGS * q + lane)]))
        return context.get_dummy_value()

    return sig, codegen


@jit
def trial_dots(y, basis, first, count, b0, b1):
    """``b0[k]`` and ``b1[k]``: the window ``y`` from lag ``first + k`` on (zeros past its end) times each column of
    ``basis`` (C-contiguous, shape (m, 2), ``m`` ≥ ``len(y) - first``), each added in order, for ``k`` below ``count``
    (lags within ``y``).

    :data:`_LAGS` lags side by side in vector lanes over the products all of them have, each lane's last products
    after.
    """
    size = len(y)
    sums = np.empty(2 * _LAGS)
    k = 0
    while k + _LAGS <= count and size - (first + k) - (_LAGS - 1) > 0:
        lag = first + k
        common = size - lag - (_LAGS - 1)
        _lag_dots(y, basis, lag, common, sums)
        for lane in range(_LAGS):
            s0, s1 = sums[lane], sums[_LAGS + lane]
            for j in range(common, size - lag - lane):
                s0 += y[lag + lane + j] * basis[j, 0]
                s1 += y[lag + lane + j] * basis[j, 1]
            b0[k + lane], b1[k + lane] = s0, s1
        k += _LAGS
    for rest in range(k, count):
        lag = first + rest
        s0, s1 = 0.0, 0.0
        for j in range(size - lag):
            s0 += y[lag + j] * basis[j, 0]
            s1 += y[lag + j] * basis[j, 1]
        b0[rest], b1[rest] = s0, s1


@jit
def measured_at(times, found, reach):
    """:func:`.onsets._measured_at`'s times: each of ``times`` moved to its nearest of ``found`` (sorted; the earlier of
    two as near) when that one is at it or up to ``reach`` samples after it and is none of ``times`` but its own."""
    out = times.copy()
    last = len(found) - 1
    for i in range(len(times)):
        t = times[i]
        nearest = min(max(np.searchsorted(found, t), 1), len(found)) - 1
        if nearest + 1 <= last and abs(found[nearest + 1] - t) < abs(found[nearest] - t):
            nearest += 1
        at = found[nearest]
        if not (at >= t and at - t <= reach):
            continue
        if at != t:
            for other in times:
                if other == at:  # a candidate of its own
                    break
            else:
                out[i] = at
    return out


@jit
def levinson(r, b):
    """The solution of the symmetric Toeplitz system whose first column is ``r`` (``len(b)`` of it) for ``b``, and
    whether it was found (False where a principal minor is singular): ``scipy.linalg.solve_toeplitz(r, b)``'s
    Levinson recursion, the same operations in the same order."""
    n = len(b)
    a = np.empty(2 * n - 1)  # scipy's layout: the first row reversed (without the diagonal), then the first column
    for j in range(n):
        a[n - 1 + j] = r[j]
        a[n - 1 - j] = r[j]
    x, g, h = np.zeros(n), np.zeros(n), np.zeros(n)
    if a[n - 1] == 0:
        return x, False
    x[0] = b[0] / a[n - 1]
    if n == 1:
        return x, True
    g[0] = a[n - 2] / a[n - 1]
    h[0] = a[n] / a[n - 1]
    for m in range(1, n):
        x_num = -b[m]
        x_den = -a[n - 1]
        if m < n - 1:  # x's sums and g's and h's read the last step's g and h: their five chains side by side
            g_num = -a[n - m - 2]
            h_num = -a[n + m]
            g_den = -a[n - 1]
            for j in range(m):
                nmj = n + m - (j + 1)
                x_num = x_num + a[nmj] * x[j]
                x_den = x_den + a[nmj] * g[m - j - 1]
                g_num = g_num + a[n + j - m - 1] * g[j]
                h_num = h_num + a[n + m - j - 1] * h[j]
                g_den = g_den + a[n + j - m - 1] * h[m - j - 1]
        else:
            for j in range(m):
                nmj = n + m - (j + 1)
                x_num = x_num + a[nmj] * x[j]
                x_den = x_den + a[nmj] * g[m - j - 1]
        if x_den == 0:
            return x, False
        x[m] = x_num / x_den
        for j in range(m):
            x[j] = x[j] - x[m] * g[m - j - 1]
        if m == n - 1:
            break
        if g_den == 0.0:
            return x, False
        g[m] = g_num / g_den
        h[m] = h_num / x_den
        k = m - 1
        c1 = g[m]
        c2 = h[m]
        for j in range((m + 1) >> 1):
            gj, gk, hj, hk = g[j], g[k], h[j], h[k]
            g[j] = gj - (c1 * hk)
            g[k] = gk - (c1 * hj)
            h[j] = hj - (c2 * gk)
            h[k] = hk - (c2 * gj)
            k -= 1
    return x, True


@intrinsic
def _four_phase_sums(typingctx, x, h, p, low, high, out):
    """``out[r] += x[m] h[4 (p - m) + r]`` for ``m`` from ``low`` to ``high - 1`` in order, the four phases ``r`` side by
    side in vector lanes (``h[4 (p - low) + 3]`` must exist)."""
    if not _contiguous(x, h, out):
        return None
    sig = types.none(x, h, p, low, high, out)

    def codegen(context, builder, signature, args):
        x_data, h_data, out_data = (context.make_array(signature.args[n])(context, builder, args[n]).data
                                    for n in (0, 1, 5))
        p, low, high = (context.cast(builder, args[n], signature.args[n], types.intp) for n in (2, 3, 4))
        total = cgutils.alloca_once_value(builder, _load_vector(builder, out_data, ir.Constant(p.type, 0)))
        with cgutils.for_range(builder, builder.sub(high, low)) as loop:
            m = builder.add(low, loop.index)
            taps = _load_vector(builder, h_data, builder.mul(builder.sub(p, m), ir.Constant(p.type, 4)))
            value = _broadcast(builder, builder.load(builder.gep(x_data, [m])))
            builder.store(builder.fadd(builder.load(total), builder.fmul(value, taps)), total)
        builder.store(builder.load(total), builder.bitcast(out_data, _VECTOR.as_pointer()), align=8)
        return context.get_dummy_value()

    return sig, codegen


@jit
def upsampled_peak(h, x):
    """``np.abs(scipy.signal.upfirdn(h, x, 4)).max()``: the largest magnitude of ``x`` upsampled 4 times by the FIR ``h``
    (each output's products added in order of ``x``'s samples: numpy's to rounding).

    Each four outputs ``4 p + r`` side by side in vector lanes: their taps ``h[4 (p - m) + r]`` are neighbours. With
    ``len(h) = 4 a + b``, the phases ``r < b`` start a sample earlier (``p - a``): that product first.
    """
    a, b = len(h) // 4, len(h) % 4
    best = 0.0
    total = np.empty(4)
    for p in range(((len(x) - 1) * 4 + len(h) - 1) // 4 + 1):  # (outputs past the last: empty sums, 0)
        low, high = max(0, p - a + 1), min(len(x), p + 1)
        for r in range(4):
            total[r] = 0.0
            if r < b and 0 <= p - a < high:
                total[r] += x[p - a] * h[4 * a + r]
        if low < high:
            _four_phase_sums(x, h, p, low, high, total)
        for r in range(4):
            best = max(best, abs(total[r]))
    return best


@jit
def _block_sum(a, low, n):
    """``np.add.reduce`` of ``a[low:low + n]`` (``n`` ≤ 128) as numpy adds a contiguous block: in 8 lanes."""
    if n < 8:
        total = -0.0
        for i in range(low, low + n):
            total += a[i]
        return total
    r0, r1, r2, r3 = a[low], a[low + 1], a[low + 2], a[low + 3]
    r4, r5, r6, r7 = a[low + 4], a[low + 5], a[low + 6], a[low + 7]
    i = 8
    while i < n - n % 8:
        r0, r1, r2, r3 = r0 + a[low + i], r1 + a[low + i + 1], r2 + a[low + i + 2], r3 + a[low + i + 3]
        r4, r5, r6, r7 = r4 + a[low + i + 4], r5 + a[low + i + 5], r6 + a[low + i + 6], r7 + a[low + i + 7]
        i += 8
    total = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    for j in range(low + i, low + n):
        total += a[j]
    return total


@jit
def _pairwise_sum(a):
    """``np.add.reduce(a)`` as numpy adds a contiguous array: halves (their split a multiple of 8) down to blocks of 128
    or fewer (:func:`_block_sum`), each half's sum added to the other's; its recursion walked with a stack (numba's
    cache does not load a recursive function)."""
    lows, counts, stages = np.empty(64, dtype=np.int64), np.empty(64, dtype=np.int64), np.zeros(64, dtype=np.int64)
    lefts = np.empty(64)
    lows[0], counts[0], depth, total = 0, len(a), 0, 0.0
    while depth >= 0:
        low, n = lows[depth], counts[depth]
        if n <= 128:
            total = _block_sum(a, low, n)
            depth -= 1
            continue
        half = n // 2 - (n // 2) % 8
        if stages[depth] == 0:  # the first half next
            stages[depth] = 1
            lows[depth + 1], counts[depth + 1], stages[depth + 1] = low, half, 0
            depth += 1
        elif stages[depth] == 1:  # the first half's sum kept, the second half next
            lefts[depth], stages[depth] = total, 2
            lows[depth + 1], counts[depth + 1], stages[depth + 1] = low + half, n - half, 0
            depth += 1
        else:
            total = lefts[depth] + total
            depth -= 1
    return total


@jit
def reweighting(e, size):
    """The weights of :func:`.onsets._robust_innovation`'s second fit: ``1 / sqrt(p + 1e-12 mean(p) + 1e-300)`` of the
    local power ``p = max(scipy.ndimage.uniform_filter1d(e * e, size), 0)`` (its running sum, at the ends the
    samples reflected), the same operations in the same order."""
    n = len(e)
    before = size // 2
    padded = np.empty(n + size - 1)  # e * e, reflected past the ends (as np.pad's "symmetric", again and again)
    for i in range(n + size - 1):
        k = i - before
        while k < 0 or k >= n:
            k = -k - 1 if k < 0 else 2 * n - k - 1
        padded[i] = e[k] * e[k]
    power = np.empty(n)
    total = 0.0
    for i in range(size):
        total += padded[i]
    power[0] = total / size
    for i in range(1, n):
        total += padded[i + size - 1] - padded[i - 1]
        power[i] = total / size
    for i in range(n):
        power[i] = max(power[i], 0.0)  # np.maximum's: a NaN stays (the running sum is never -0)
    floor = 1e-12 * ((0.0 + _pairwise_sum(power)) / n)  # numpy's mean: the sum from 0, over the count
    weight = np.empty(n)
    for i in range(n):
        weight[i] = 1.0 / np.sqrt(power[i] + floor + 1e-300)
    return weight
