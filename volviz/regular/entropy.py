"""Entropy coding of wavelet bricks (Guthe §2.2.2): sign mapping, significance map, zero-subtree stripping and two
coders.

Scan order (shared by both coders). A tile's seven detail subbands ``b = 1..7`` (bit ``a`` of ``b`` set = axis
``a`` highpass) are visited in order; each subband is cut into 4^3 sub-blocks. A one-bit significance flag per
subband and per sub-block (the significance map) says whether it holds any non-zero coefficient; only significant
sub-blocks carry coefficients. An all-zero tile codes to zero bytes (a stripped node, see ``codec``). Context class
of a subband = number of highpass axes - 1 (0, 1, 2); class 3 is the root's lowpass residual.

``CODER_RANS`` (the fast coder; a replacement of the thesis's fixed gamma-Huffman, chosen by measurement):
coefficients are sign mapped (c -> 2c for c >= 0, -2c-1 for c < 0, the thesis's mapping) to v. Tokens are v for
v < 16 and ``11 + bitlength(v)`` otherwise, followed by the bits of v below its leading one as raw bits (the thesis's
gamma-code structure). Tokens are coded with a static rANS coder (32-bit state, 16-bit renormalisation, 12-bit
probabilities; version 2: two interleaved states, token n uses state n & 1, so the decoder runs two independent
dependency chains -- about 25% faster entropy decoding than one state) whose per-class frequency tables are stored in
the brick. Node layout::

    u32 nbytes of the bit section | bit section (LSB first: significance map, tables, raw bits) |
    rANS u16 words (state 0 as two words, high first; state 1 likewise; then the renormalisation words)

``CODER_ARITH`` (the high-ratio option; Guthe's adaptive arithmetic coder of [GS04] in spirit, version 2): an
LZMA-style adaptive binary range coder (15-bit probabilities; the adaptation rate starts at 1/2 and slows to 1/128 as
a context is used, so the contexts of a small brick learn quickly) codes the significance map with the previous flag
as context and each coefficient as zero flag, sign, unary bit length and mantissa bits. Contexts: the class, the
bucketed magnitude sum of the three causal neighbours (previous sample along each axis in the same subband) plus the
magnitudes at the same position in the subbands already coded (cross-subband), and -- in lossless files only, where
the decoder's lowpass equals the encoder's -- the bucketed activity (3^3 max - min) of the lowpass at that position.
Version 2's contexts and adaptation rate raised the ratio over version 1's (causal neighbours only, fixed rate 1/16),
lossless and lossy (docs/bench/docstring-figures.md). A damaged coarse brick in a lossless arith file also
perturbs the contexts of its children, whose region is then approximate too (it is the damaged region anyway).

Version 3 adds the model of bricks coded with the integer S-transform (lossless files, see ``wavelet.py``):
:func:`encode_haar_arith` visits the details block by block (the 7 details of one 2x2x2 voxel block together, with
a per-block significance flag) instead of subband by subband, with contexts from the block's lowpass, its
neighbours' lowpass and the causal neighbour blocks' details, and an S+P-style prediction of the single-axis details
from the lowpass slope. The rANS coder codes S-transform bricks with its unchanged subband scan. Letting every node
choose the smaller of 5/3 and S-transform raises both coders' lossless ratio (docs/bench/docstring-figures.md).
"""
from __future__ import annotations

import numpy as np
from numba import njit

CODER_RANS = 0
CODER_ARITH = 1
CODERS = {"rans": CODER_RANS, "arith": CODER_ARITH}
CODER_VERSION = {"rans": 2, "arith": 3}  # rans 2: two interleaved states; arith 2: new contexts; 3: S-transform model

SB = 4  # sub-block edge of the significance map
HALF_T = 16  # largest subband edge of a 32^3 tile (and of the root)
N_TOK = 48
PROB_BITS = 12
PROB_SCALE = 1 << PROB_BITS
RANS_L = 1 << 16
N_CLASS = 4


@njit(cache=True, nogil=True)
def sign_map(c):
    """Guthe §2.2.2 sign mapping: c -> 2c (c >= 0), -2c - 1 (c < 0)."""
    return 2 * c if c >= 0 else -2 * c - 1


@njit(cache=True, nogil=True)
def sign_unmap(v):
    return v >> 1 if (v & 1) == 0 else -((v + 1) >> 1)


@njit(cache=True, nogil=True)
def _bitlen(v):
    n = 0
    while v > 0:
        v >>= 1
        n += 1
    return n


@njit(cache=True, nogil=True)
def regions(n0, n1, n2, root):
    """Coded regions of a tile: rows (lo0, hi0, lo1, hi1, lo2, hi2, class). ``root``: the whole box, class 3."""
    out = np.zeros((7, 7), np.int64)
    if root:
        out[0, 1] = n0
        out[0, 3] = n1
        out[0, 5] = n2
        out[0, 6] = 3
        return out[:1]
    l0 = (n0 + 1) // 2
    l1 = (n1 + 1) // 2
    l2 = (n2 + 1) // 2
    m = 0
    for b in range(1, 8):
        h0 = b & 1
        h1 = (b >> 1) & 1
        h2 = (b >> 2) & 1
        out[m, 0] = l0 if h0 else 0
        out[m, 1] = n0 if h0 else l0
        out[m, 2] = l1 if h1 else 0
        out[m, 3] = n1 if h1 else l1
        out[m, 4] = l2 if h2 else 0
        out[m, 5] = n2 if h2 else l2
        out[m, 6] = h0 + h1 + h2 - 1
        if out[m, 1] > out[m, 0] and out[m, 3] > out[m, 2] and out[m, 5] > out[m, 4]:
            m += 1
    return out[:m]


@njit(cache=True, nogil=True)
def _put_bits(buf, base, bitpos, value, n):
    """Write the n low bits of value at bit position bitpos (LSB first); buf must be zeroed there."""
    for i in range(n):
        if (value >> i) & 1:
            p = bitpos + i
            buf[base + (p >> 3)] |= np.uint8(1 << (p & 7))
    return bitpos + n


@njit(cache=True, nogil=True)
def _get_bits(buf, base, limit, bitpos, n):
    """Read n <= 32 bits at bitpos (LSB first); bytes at or beyond ``limit`` read as zero."""
    value = np.int64(0)
    got = 0
    p = bitpos
    while got < n:
        byte = base + (p >> 3)
        sh = p & 7
        take = min(8 - sh, n - got)
        b = np.int64(buf[byte]) if byte < limit else np.int64(0)
        value |= ((b >> sh) & ((1 << take) - 1)) << got
        got += take
        p += take
    return value


@njit(cache=True, nogil=True)
def _sig_map(w, reg, sig, anyflag):
    """Fill the significance map of all regions; returns number of significant sub-blocks."""
    total = 0
    for r in range(reg.shape[0]):
        lo0, hi0, lo1, hi1, lo2, hi2 = reg[r, 0], reg[r, 1], reg[r, 2], reg[r, 3], reg[r, 4], reg[r, 5]
        q = 0
        anyflag[r] = 0
        for b0 in range(lo0, hi0, SB):
            for b1 in range(lo1, hi1, SB):
                for b2 in range(lo2, hi2, SB):
                    s = 0
                    for i in range(b0, min(b0 + SB, hi0)):
                        for j in range(b1, min(b1 + SB, hi1)):
                            for k in range(b2, min(b2 + SB, hi2)):
                                if w[i, j, k] != 0:
                                    s = 1
                                    break
                            if s:
                                break
                        if s:
                            break
                    sig[r, q] = s
                    if s:
                        anyflag[r] = 1
                        total += 1
                    q += 1
    return total


@njit(cache=True, nogil=True)
def zero_regions(w, reg):
    """Set every coded coefficient to zero (a stripped node or a damaged brick)."""
    for r in range(reg.shape[0]):
        for i in range(reg[r, 0], reg[r, 1]):
            for j in range(reg[r, 2], reg[r, 3]):
                for k in range(reg[r, 4], reg[r, 5]):
                    w[i, j, k] = 0


# ----------------------------------------------------------------------------------------------------------- rANS
@njit(cache=True, nogil=True)
def _normalise(counts, freq):
    total = counts.sum()
    if total == 0:
        return
    acc = 0
    big = 0
    for s in range(N_TOK):
        if counts[s] > 0:
            f = max(1, (counts[s] * PROB_SCALE) // total)
            freq[s] = f
            acc += f
            if f > freq[big] or counts[big] == 0:
                big = s
    while acc != PROB_SCALE:
        if acc > PROB_SCALE:
            # take from the largest symbols that can spare it
            best = -1
            for s in range(N_TOK):
                if freq[s] > 1 and (best < 0 or freq[s] > freq[best]):
                    best = s
            take = min(acc - PROB_SCALE, freq[best] - 1)
            freq[best] -= take
            acc -= take
        else:
            freq[big] += PROB_SCALE - acc
            acc = PROB_SCALE


@njit(cache=True, nogil=True)
def encode_rans(w, n0, n1, n2, root, out, base):
    """Encode a tile (details, or the whole box if ``root``) into ``out[base:]``; returns the byte count (0 = all
    zero). ``out`` must be zeroed from ``base`` on and large enough (:func:`capacity`)."""
    reg = regions(n0, n1, n2, root)
    nreg = reg.shape[0]
    sig = np.zeros((7, 512), np.uint8)
    anyflag = np.zeros(7, np.uint8)
    if _sig_map(w, reg, sig, anyflag) == 0:
        return 0
    ncoef = 0
    for r in range(nreg):
        ncoef += (reg[r, 1] - reg[r, 0]) * (reg[r, 3] - reg[r, 2]) * (reg[r, 5] - reg[r, 4])
    tok = np.empty(ncoef, np.uint8)
    tcls = np.empty(ncoef, np.uint8)
    counts = np.zeros((N_CLASS, N_TOK), np.int64)
    hdr = base + 4
    bp = 0
    # significance map
    for r in range(nreg):
        bp = _put_bits(out, hdr, bp, anyflag[r], 1)
    for r in range(nreg):
        if anyflag[r]:
            q = 0
            for b0 in range(reg[r, 0], reg[r, 1], SB):
                for b1 in range(reg[r, 2], reg[r, 3], SB):
                    for b2 in range(reg[r, 4], reg[r, 5], SB):
                        bp = _put_bits(out, hdr, bp, sig[r, q], 1)
                        q += 1
    # tokens
    nt = 0
    for r in range(nreg):
        if not anyflag[r]:
            continue
        c = reg[r, 6]
        q = 0
        for b0 in range(reg[r, 0], reg[r, 1], SB):
            for b1 in range(reg[r, 2], reg[r, 3], SB):
                for b2 in range(reg[r, 4], reg[r, 5], SB):
                    if sig[r, q]:
                        for i in range(b0, min(b0 + SB, reg[r, 1])):
                            for j in range(b1, min(b1 + SB, reg[r, 3])):
                                for k in range(b2, min(b2 + SB, reg[r, 5])):
                                    v = sign_map(np.int64(w[i, j, k]))
                                    t = v if v < 16 else 11 + _bitlen(v)
                                    tok[nt] = t
                                    tcls[nt] = c
                                    counts[c, t] += 1
                                    nt += 1
                    q += 1
    # tables: per class, 6-bit (max token + 1), presence bits, 12-bit freq - 1
    freq = np.zeros((N_CLASS, N_TOK), np.int64)
    start = np.zeros((N_CLASS, N_TOK), np.int64)
    for c in range(N_CLASS):
        _normalise(counts[c], freq[c])
        top = 0
        for s in range(N_TOK):
            if freq[c, s] > 0:
                top = s + 1
        bp = _put_bits(out, hdr, bp, top, 6)
        for s in range(top):
            bp = _put_bits(out, hdr, bp, 1 if freq[c, s] > 0 else 0, 1)
        acc = 0
        for s in range(top):
            if freq[c, s] > 0:
                bp = _put_bits(out, hdr, bp, freq[c, s] - 1, PROB_BITS)
                start[c, s] = acc
                acc += freq[c, s]
    # raw mantissa bits in token order
    nt2 = 0
    for r in range(nreg):
        if not anyflag[r]:
            continue
        q = 0
        for b0 in range(reg[r, 0], reg[r, 1], SB):
            for b1 in range(reg[r, 2], reg[r, 3], SB):
                for b2 in range(reg[r, 4], reg[r, 5], SB):
                    if sig[r, q]:
                        for i in range(b0, min(b0 + SB, reg[r, 1])):
                            for j in range(b1, min(b1 + SB, reg[r, 3])):
                                for k in range(b2, min(b2 + SB, reg[r, 5])):
                                    t = tok[nt2]
                                    if t >= 16:
                                        v = sign_map(np.int64(w[i, j, k]))
                                        nb = t - 11
                                        bp = _put_bits(out, hdr, bp, v & ((1 << (nb - 1)) - 1), nb - 1)
                                    nt2 += 1
                    q += 1
    nbytes_bits = (bp + 15) // 16 * 2
    out[base] = nbytes_bits & 0xFF
    out[base + 1] = (nbytes_bits >> 8) & 0xFF
    out[base + 2] = (nbytes_bits >> 16) & 0xFF
    out[base + 3] = (nbytes_bits >> 24) & 0xFF
    # rANS with two interleaved states (token n uses state n & 1), tokens in reverse, words written backwards
    words = np.empty(nt + 8, np.uint16)
    pos = nt + 8
    x0 = np.uint64(RANS_L)
    x1 = np.uint64(RANS_L)
    for n in range(nt - 1, -1, -1):
        c = tcls[n]
        t = tok[n]
        f = np.uint64(freq[c, t])
        x = x1 if n & 1 else x0
        x_max = np.uint64(((RANS_L >> PROB_BITS) << 16)) * f
        if x >= x_max:
            pos -= 1
            words[pos] = np.uint16(x & np.uint64(0xFFFF))
            x >>= np.uint64(16)
        x = ((x // f) << np.uint64(PROB_BITS)) + (x % f) + np.uint64(start[c, t])
        if n & 1:
            x1 = x
        else:
            x0 = x
    for x in (x1, x0):  # the decoder reads x0 first
        pos -= 1
        words[pos] = np.uint16(x & np.uint64(0xFFFF))
        pos -= 1
        words[pos] = np.uint16(x >> np.uint64(16))
    o = hdr + nbytes_bits
    for n in range(pos, nt + 8):
        out[o] = words[n] & 0xFF
        out[o + 1] = words[n] >> 8
        o += 2
    return o - base


@njit(cache=True, nogil=True)
def decode_rans(buf, base, length, w, n0, n1, n2, root):
    """Decode a node written by :func:`encode_rans` into the tile buffer ``w`` (coded regions only). Returns 0 on
    success, -1 if the stream is inconsistent (a damaged brick that passed its checksum is still caught).

    Speed: one packed table entry per rANS slot (token | freq << 6 | start << 19), a 64-bit buffered reader for
    the raw mantissa bits and the sign unmapping fused into the store (``(v >> 1) ^ -(v & 1)``); about 2x faster
    than a per-bit reader."""
    reg = regions(n0, n1, n2, root)
    nreg = reg.shape[0]
    if length == 0:
        zero_regions(w, reg)
        return 0
    if length < 4:
        return -1
    nbb = np.int64(buf[base]) | (np.int64(buf[base + 1]) << 8) | (np.int64(buf[base + 2]) << 16) | (
        np.int64(buf[base + 3]) << 24)
    if nbb > length - 4:
        return -1
    hdr = base + 4
    limit = hdr + nbb
    bp = 0
    anyflag = np.zeros(7, np.uint8)
    sig = np.zeros((7, 512), np.uint8)
    for r in range(nreg):
        anyflag[r] = _get_bits(buf, hdr, limit, bp, 1)
        bp += 1
    for r in range(nreg):
        if not anyflag[r]:
            continue
        nq = (((reg[r, 1] - reg[r, 0] + SB - 1) // SB) * ((reg[r, 3] - reg[r, 2] + SB - 1) // SB)
              * ((reg[r, 5] - reg[r, 4] + SB - 1) // SB))
        for q in range(nq):
            sig[r, q] = _get_bits(buf, hdr, limit, bp, 1)
            bp += 1
    lut = np.empty((N_CLASS, PROB_SCALE), np.int32)
    present = np.zeros(N_CLASS, np.uint8)
    for c in range(N_CLASS):
        top = _get_bits(buf, hdr, limit, bp, 6)
        bp += 6
        if top > N_TOK:
            return -1
        pres = np.zeros(N_TOK, np.uint8)
        for s in range(top):
            pres[s] = _get_bits(buf, hdr, limit, bp, 1)
            bp += 1
        acc = 0
        for s in range(top):
            if pres[s]:
                f = _get_bits(buf, hdr, limit, bp, PROB_BITS) + 1
                bp += PROB_BITS
                if acc + f > PROB_SCALE:
                    return -1
                e = s | (f << 6) | (acc << 19)
                for u in range(acc, acc + f):
                    lut[c, u] = e
                acc += f
        if top > 0:
            if acc != PROB_SCALE:
                return -1
            present[c] = 1
    if bp > nbb * 8:
        return -1
    o = limit
    end = base + length
    if o + 8 > end:
        return -1
    x0 = ((np.int64(buf[o]) | (np.int64(buf[o + 1]) << 8)) << 16) | np.int64(buf[o + 2]) | (
        np.int64(buf[o + 3]) << 8)
    x1 = ((np.int64(buf[o + 4]) | (np.int64(buf[o + 5]) << 8)) << 16) | np.int64(buf[o + 6]) | (
        np.int64(buf[o + 7]) << 8)
    o += 8
    par = 0
    # buffered raw-bit reader over [hdr, limit), positioned at bit bp
    rp = hdr + (bp >> 3)
    bits = np.int64(0)
    nbits = 0
    while nbits <= 48 and rp < limit:
        bits |= np.int64(buf[rp]) << nbits
        nbits += 8
        rp += 1
    skip = bp & 7
    bits >>= skip
    nbits -= skip
    used = bp
    for r in range(nreg):
        c = reg[r, 6]
        if anyflag[r] and not present[c]:
            return -1
        lut_c = lut[c]
        q = 0
        for b0 in range(reg[r, 0], reg[r, 1], SB):
            e0 = min(b0 + SB, reg[r, 1])
            for b1 in range(reg[r, 2], reg[r, 3], SB):
                e1 = min(b1 + SB, reg[r, 3])
                for b2 in range(reg[r, 4], reg[r, 5], SB):
                    e2 = min(b2 + SB, reg[r, 5])
                    if sig[r, q]:
                        for i in range(b0, e0):
                            for j in range(b1, e1):
                                wl = w[i, j]
                                for k in range(b2, e2):
                                    if par == 0:
                                        slot = x0 & (PROB_SCALE - 1)
                                        e = np.int64(lut_c[slot])
                                        x0 = ((e >> 6) & 0x1FFF) * (x0 >> PROB_BITS) + slot - (e >> 19)
                                        if x0 < RANS_L:
                                            if o + 2 <= end:
                                                x0 = (x0 << 16) | np.int64(buf[o]) | (np.int64(buf[o + 1]) << 8)
                                            else:
                                                x0 = x0 << 16
                                            o += 2
                                    else:
                                        slot = x1 & (PROB_SCALE - 1)
                                        e = np.int64(lut_c[slot])
                                        x1 = ((e >> 6) & 0x1FFF) * (x1 >> PROB_BITS) + slot - (e >> 19)
                                        if x1 < RANS_L:
                                            if o + 2 <= end:
                                                x1 = (x1 << 16) | np.int64(buf[o]) | (np.int64(buf[o + 1]) << 8)
                                            else:
                                                x1 = x1 << 16
                                            o += 2
                                    par ^= 1
                                    t = e & 63
                                    if t < 16:
                                        v = t
                                    else:
                                        nb = t - 12
                                        if nbits < nb:
                                            while nbits <= 48:
                                                if rp < limit:
                                                    bits |= np.int64(buf[rp]) << nbits
                                                rp += 1
                                                nbits += 8
                                        v = (np.int64(1) << nb) | (bits & ((np.int64(1) << nb) - 1))
                                        bits >>= nb
                                        nbits -= nb
                                        used += nb
                                    wl[k] = (v >> 1) ^ -(v & 1)
                    else:
                        for i in range(b0, e0):
                            for j in range(b1, e1):
                                for k in range(b2, e2):
                                    w[i, j, k] = 0
                    q += 1
    if o > end + 2 or used > nbb * 8:
        return -1
    return 0


# ------------------------------------------------------------------------------------------- adaptive arithmetic
_PB = 15
_PTOT = 1 << _PB
_SHIFT = 7
_TOP = 1 << 24
N_NB = 10  # buckets of the causal neighbour + cross-subband magnitude sum
N_ACT = 6  # buckets of the lowpass activity (lossless only)
N_EXP = 24
_P_ANY = 0
_P_SIG = _P_ANY + N_CLASS
_P_ZERO = _P_SIG + N_CLASS * 2
_P_SIGN = _P_ZERO + N_CLASS * N_ACT * N_NB
_P_EXP = _P_SIGN + N_CLASS
_P_MAN = _P_EXP + N_CLASS * 3 * N_NB * N_EXP
N_PROBS = _P_MAN + N_CLASS * 32


_NB_EDGES = np.array([1, 2, 3, 5, 9, 17, 33, 65, 129], np.int64)  # N_NB buckets of magnitude sums
_ACT_EDGES = np.array([1, 3, 9, 33, 129], np.int64)  # N_ACT buckets of lowpass activity


@njit(cache=True, nogil=True)
def _bucket(s, edges):
    """Number of ``edges`` that ``s`` reaches (0..len(edges))."""
    b = 0
    while b < edges.shape[0] and s >= edges[b]:
        b += 1
    return b


@njit(cache=True, nogil=True)
def _shift_low(st, out):
    # st: [low, range, cache, cache_size, pos]
    low = st[0]
    if low < 0xFF000000 or low >= (1 << 32):
        carry = low >> 32
        temp = st[2]
        while True:
            out[st[4]] = (temp + carry) & 0xFF
            st[4] += 1
            temp = 0xFF
            st[3] -= 1
            if st[3] == 0:
                break
        st[2] = (low >> 24) & 0xFF
    st[3] += 1
    st[0] = (low & 0x00FFFFFF) << 8


@njit(cache=True, nogil=True)
def _adapt(probs, idx, bit):
    """Update a context: ``probs[idx]`` packs the 15-bit probability of a 0 and (above bit 16) how often the
    context was used; the adaptation rate starts at 1/2 and slows to 1/2^_SHIFT (running average at first,
    then exponential forgetting), so the many contexts of a small brick learn quickly."""
    e = probs[idx]
    p = e & 0xFFFF
    n = e >> 16
    sh = min(_bitlen(n + 1), _SHIFT)
    if bit == 0:
        p += (_PTOT - p) >> sh
    else:
        p -= p >> sh
    probs[idx] = p | (min(n + 1, 63) << 16)


@njit(cache=True, nogil=True)
def _enc_bit(st, out, probs, idx, bit):
    p = probs[idx] & 0xFFFF
    bound = (st[1] >> _PB) * p
    if bit == 0:
        st[1] = bound
    else:
        st[0] += bound
        st[1] -= bound
    _adapt(probs, idx, bit)
    while st[1] < _TOP:
        st[1] <<= 8
        _shift_low(st, out)


@njit(cache=True, nogil=True)
def _enc_direct(st, out, value, n):
    for i in range(n - 1, -1, -1):
        st[1] >>= 1
        if (value >> i) & 1:
            st[0] += st[1]
        while st[1] < _TOP:
            st[1] <<= 8
            _shift_low(st, out)


@njit(cache=True, nogil=True)
def _dec_bit(st, buf, probs, idx):
    # st: [code, range, pos, end]
    p = probs[idx] & 0xFFFF
    bound = (st[1] >> _PB) * p
    if st[0] < bound:
        st[1] = bound
        bit = 0
    else:
        st[0] -= bound
        st[1] -= bound
        bit = 1
    _adapt(probs, idx, bit)
    while st[1] < _TOP:
        st[1] <<= 8
        b = buf[st[2]] if st[2] < st[3] else 0
        st[0] = ((st[0] << 8) | b) & 0xFFFFFFFF
        st[2] += 1
    return bit


@njit(cache=True, nogil=True)
def _enc_init(base):
    """Range encoder state [low, range, cache, cache_size, pos] writing from ``base``."""
    st = np.zeros(5, np.int64)
    st[1] = 0xFFFFFFFF
    st[3] = 1
    st[4] = base
    return st


@njit(cache=True, nogil=True)
def _dec_init(buf, base, length):
    """Range decoder state [code, range, pos, end] of the stream ``buf[base:base + length]`` (length >= 5)."""
    st = np.zeros(4, np.int64)
    st[1] = 0xFFFFFFFF
    st[2] = base + 1
    st[3] = base + length
    for _ in range(4):
        st[0] = (st[0] << 8) | buf[st[2]]
        st[2] += 1
    return st


@njit(cache=True, nogil=True)
def _dec_direct(st, buf, n):
    v = 0
    for _ in range(n):
        st[1] >>= 1
        bit = 0
        if st[0] >= st[1]:
            st[0] -= st[1]
            bit = 1
        v = (v << 1) | bit
        while st[1] < _TOP:
            st[1] <<= 8
            b = buf[st[2]] if st[2] < st[3] else 0
            st[0] = ((st[0] << 8) | b) & 0xFFFFFFFF
            st[2] += 1
    return v


@njit(cache=True, nogil=True, inline="always")
def _enc_magnitude(st, out, probs, ectx, mctx, m):
    """A magnitude m >= 1: its bit length e in unary (contexts ``ectx + min(u, N_EXP - 1)``), the bit below the
    leading one (context ``mctx + min(e, 31)``), then the remaining e - 2 bits directly."""
    e = _bitlen(m)
    for u in range(1, e):
        _enc_bit(st, out, probs, ectx + min(u, N_EXP - 1), 1)
    _enc_bit(st, out, probs, ectx + min(e, N_EXP - 1), 0)
    if e >= 2:
        _enc_bit(st, out, probs, mctx + min(e, 31), (m >> (e - 2)) & 1)
        if e >= 3:
            _enc_direct(st, out, m & ((1 << (e - 2)) - 1), e - 2)


@njit(cache=True, nogil=True, inline="always")
def _dec_magnitude(st, buf, probs, ectx, mctx):
    """Inverse of :func:`_enc_magnitude`; -1 on an inconsistent stream (a bit length over 40)."""
    e = 1
    while _dec_bit(st, buf, probs, ectx + min(e, N_EXP - 1)) == 1:
        e += 1
        if e > 40:
            return np.int64(-1)
    m = np.int64(1)
    if e >= 2:
        m = (m << 1) | _dec_bit(st, buf, probs, mctx + min(e, 31))
        if e >= 3:
            m = (m << (e - 2)) | _dec_direct(st, buf, e - 2)
    return m


@njit(cache=True, nogil=True)
def _activity_map(w, l0, l1, l2, am):
    """``am[p]`` = bucket of (max - min) of the lowpass ``w[:l0, :l1, :l2]`` over the 3^3 neighbourhood of p
    (clamped at the borders; separable, one axis per pass): the local activity of the coarser level, which
    predicts the detail magnitudes."""
    mx = np.empty((HALF_T, HALF_T, HALF_T), np.int64)
    mn = np.empty((HALF_T, HALF_T, HALF_T), np.int64)
    mx2 = np.empty((HALF_T, HALF_T, HALF_T), np.int64)
    mn2 = np.empty((HALF_T, HALF_T, HALF_T), np.int64)
    for i in range(l0):
        for j in range(l1):
            for k in range(l2):
                ka = max(k - 1, 0)
                kb = min(k + 1, l2 - 1)
                mx[i, j, k] = max(w[i, j, k], max(w[i, j, ka], w[i, j, kb]))
                mn[i, j, k] = min(w[i, j, k], min(w[i, j, ka], w[i, j, kb]))
    for i in range(l0):
        for j in range(l1):
            ja = max(j - 1, 0)
            jb = min(j + 1, l1 - 1)
            for k in range(l2):
                mx2[i, j, k] = max(mx[i, j, k], max(mx[i, ja, k], mx[i, jb, k]))
                mn2[i, j, k] = min(mn[i, j, k], min(mn[i, ja, k], mn[i, jb, k]))
    for i in range(l0):
        ia = max(i - 1, 0)
        ib = min(i + 1, l0 - 1)
        for j in range(l1):
            for k in range(l2):
                hi = max(mx2[i, j, k], max(mx2[ia, j, k], mx2[ib, j, k]))
                lo = min(mn2[i, j, k], min(mn2[ia, j, k], mn2[ib, j, k]))
                am[i, j, k] = _bucket(hi - lo, _ACT_EDGES)


@njit(cache=True, nogil=True)
def _contexts(w, i, j, k, lo0, lo1, lo2, cs, am, c):
    """Zero-flag and magnitude context of coefficient (i, j, k) of a subband starting at (lo0, lo1, lo2)."""
    p0 = i - lo0
    p1 = j - lo1
    p2 = k - lo2
    s = cs[p0, p1, p2]
    if p0 > 0:
        s += abs(w[i - 1, j, k])
    if p1 > 0:
        s += abs(w[i, j - 1, k])
    if p2 > 0:
        s += abs(w[i, j, k - 1])
    nbb = _bucket(s, _NB_EDGES)
    a = am[p0, p1, p2]
    return (c * N_ACT + a) * N_NB + nbb, ((c * 3 + min(a, 2)) * N_NB + nbb) * N_EXP


@njit(cache=True, nogil=True)
def encode_arith(w, n0, n1, n2, root, out, base, uselow=False):
    """Adaptive binary arithmetic coding of a tile into ``out[base:]``; returns the byte count (0 = all zero).

    ``uselow``: the lowpass ``w[:l0, :l1, :l2]`` is known exactly to the decoder (lossless files), so its local
    activity joins the contexts."""
    reg = regions(n0, n1, n2, root)
    nreg = reg.shape[0]
    sig = np.zeros((7, 512), np.uint8)
    anyflag = np.zeros(7, np.uint8)
    if _sig_map(w, reg, sig, anyflag) == 0:
        return 0
    cs = np.zeros((HALF_T, HALF_T, HALF_T), np.int64)
    am = np.zeros((HALF_T, HALF_T, HALF_T), np.uint8)
    if uselow and not root:
        _activity_map(w, (n0 + 1) // 2, (n1 + 1) // 2, (n2 + 1) // 2, am)
    probs = np.full(N_PROBS, _PTOT // 2, np.int64)
    st = _enc_init(base)
    for r in range(nreg):
        c = reg[r, 6]
        _enc_bit(st, out, probs, _P_ANY + c, anyflag[r])
        if not anyflag[r]:
            continue
        lo0, hi0, lo1, hi1, lo2, hi2 = reg[r, 0], reg[r, 1], reg[r, 2], reg[r, 3], reg[r, 4], reg[r, 5]
        q = 0
        prev = 1
        for b0 in range(lo0, hi0, SB):
            for b1 in range(lo1, hi1, SB):
                for b2 in range(lo2, hi2, SB):
                    s = sig[r, q]
                    _enc_bit(st, out, probs, _P_SIG + 2 * c + prev, s)
                    prev = s
                    q += 1
                    if not s:
                        continue
                    for i in range(b0, min(b0 + SB, hi0)):
                        for j in range(b1, min(b1 + SB, hi1)):
                            for k in range(b2, min(b2 + SB, hi2)):
                                ctx, ectx = _contexts(w, i, j, k, lo0, lo1, lo2, cs, am, c)
                                v = np.int64(w[i, j, k])
                                if v == 0:
                                    _enc_bit(st, out, probs, _P_ZERO + ctx, 0)
                                    continue
                                _enc_bit(st, out, probs, _P_ZERO + ctx, 1)
                                _enc_bit(st, out, probs, _P_SIGN + c, 1 if v < 0 else 0)
                                m = abs(v)
                                cs[i - lo0, j - lo1, k - lo2] += m
                                _enc_magnitude(st, out, probs, _P_EXP + ectx, _P_MAN + c * 32, m)
    for _ in range(5):
        _shift_low(st, out)
    return st[4] - base


@njit(cache=True, nogil=True)
def decode_arith(buf, base, length, w, n0, n1, n2, root, uselow=False):
    """Decode a node written by :func:`encode_arith` into ``w`` (with the same ``uselow``: the lowpass must be in
    ``w`` already); returns 0 (or -1 on an inconsistent stream)."""
    reg = regions(n0, n1, n2, root)
    nreg = reg.shape[0]
    if length == 0:
        zero_regions(w, reg)
        return 0
    if length < 5:
        return -1
    cs = np.zeros((HALF_T, HALF_T, HALF_T), np.int64)
    am = np.zeros((HALF_T, HALF_T, HALF_T), np.uint8)
    if uselow and not root:
        _activity_map(w, (n0 + 1) // 2, (n1 + 1) // 2, (n2 + 1) // 2, am)
    probs = np.full(N_PROBS, _PTOT // 2, np.int64)
    st = _dec_init(buf, base, length)
    for r in range(nreg):
        c = reg[r, 6]
        lo0, hi0, lo1, hi1, lo2, hi2 = reg[r, 0], reg[r, 1], reg[r, 2], reg[r, 3], reg[r, 4], reg[r, 5]
        anyf = _dec_bit(st, buf, probs, _P_ANY + c)
        q = 0
        prev = 1
        for b0 in range(lo0, hi0, SB):
            for b1 in range(lo1, hi1, SB):
                for b2 in range(lo2, hi2, SB):
                    e0 = min(b0 + SB, hi0)
                    e1 = min(b1 + SB, hi1)
                    e2 = min(b2 + SB, hi2)
                    s = 0
                    if anyf:
                        s = _dec_bit(st, buf, probs, _P_SIG + 2 * c + prev)
                        prev = s
                    q += 1
                    if not s:
                        for i in range(b0, e0):
                            for j in range(b1, e1):
                                for k in range(b2, e2):
                                    w[i, j, k] = 0
                        continue
                    for i in range(b0, e0):
                        for j in range(b1, e1):
                            for k in range(b2, e2):
                                ctx, ectx = _contexts(w, i, j, k, lo0, lo1, lo2, cs, am, c)
                                if _dec_bit(st, buf, probs, _P_ZERO + ctx) == 0:
                                    w[i, j, k] = 0
                                    continue
                                neg = _dec_bit(st, buf, probs, _P_SIGN + c)
                                m = _dec_magnitude(st, buf, probs, _P_EXP + ectx, _P_MAN + c * 32)
                                if m < 0:
                                    return -1
                                cs[i - lo0, j - lo1, k - lo2] += m
                                w[i, j, k] = -m if neg else m
    if st[2] > st[3] + 4:
        return -1
    return 0


def capacity(n_coef: int) -> int:
    """Worst-case byte count of a coded tile of ``n_coef`` coefficients (both coders)."""
    return 6 * n_coef + 4096


# ------------------------------------------------------- arith v3: block-interleaved coder for S-transform tiles
# Probability layout of :func:`encode_haar_arith` (see its docstring).
_NB7 = 7  # buckets of a magnitude (0, 1, 2, 3-4, 5-8, 9-16, 17+)
_HB_BLOCK = 0
_HB_ZERO = _HB_BLOCK + _NB7 * _NB7 * _NB7
_HB_SIGN = _HB_ZERO + 8 * _NB7 * _NB7 * 3 * 3
_HB_EXP = _HB_SIGN + 8 * 2 * 3
_HB_MAN = _HB_EXP + 8 * _NB7 * _NB7 * 3 * N_EXP
N_HPROBS = _HB_MAN + 8 * 32


@njit(cache=True, nogil=True)
def _b7(v):
    """Bucket 0..6 of a non-negative magnitude: 0, 1, 2, 3-4, 5-8, 9-16, 17+."""
    if v <= 2:
        return v
    if v <= 4:
        return 3
    if v <= 8:
        return 4
    if v <= 16:
        return 5
    return 6


@njit(cache=True, nogil=True, inline="always")
def _hhas(i, j, k, h0, h1, h2, sb):
    """Whether block (i, j, k) of an S-transform tile has a detail in subband ``sb`` (odd sizes lack the last one)."""
    return not ((sb & 1 and i >= h0) or (sb & 2 and j >= h1) or (sb & 4 and k >= h2))


@njit(cache=True, nogil=True, inline="always")
def _hat(i, j, k, l0, l1, l2, sb):
    """Index of the subband ``sb`` detail of block (i, j, k) in an S-transform tile."""
    return l0 + i if sb & 1 else i, l1 + j if sb & 2 else j, l2 + k if sb & 4 else k


@njit(cache=True, nogil=True, inline="always")
def _hsign_ctx(sb, lb, pr):
    """Sign context of a non-zero residual: subband, lowpass zero or not, sign of the prediction."""
    return _HB_SIGN + ((sb * 2 + (1 if lb > 0 else 0)) * 3 + (0 if pr == 0 else (1 if pr > 0 else 2)))


@njit(cache=True, nogil=True, inline="always")
def _hexp_ctx(sb, lb, nb, inb, pb):
    """Magnitude context: subband, lowpass bucket, the larger of the neighbour and in-block sizes, prediction size."""
    return _HB_EXP + (((sb * _NB7 + lb) * _NB7 + max(nb, _b7(inb))) * 3 + pb) * N_EXP


@njit(cache=True, nogil=True)
def _hblock(w, i, j, k, l0, l1, l2, h0, h1, h2):
    """Block contexts of lowpass position (i, j, k) of an S-transform tile: (bucket of |L|, bucket of half the
    detail magnitudes of the three causal neighbour blocks, bucket of the largest |L| of the six face neighbours)."""
    n = 0
    for a in range(3):
        x = i - 1 if a == 0 else i
        y = j - 1 if a == 1 else j
        z = k - 1 if a == 2 else k
        if x < 0 or y < 0 or z < 0:
            continue
        for sb in range(1, 8):
            if _hhas(x, y, z, h0, h1, h2, sb):
                n += abs(w[_hat(x, y, z, l0, l1, l2, sb)])
    am = 0
    if i > 0:
        am = max(am, abs(w[i - 1, j, k]))
    if i + 1 < l0:
        am = max(am, abs(w[i + 1, j, k]))
    if j > 0:
        am = max(am, abs(w[i, j - 1, k]))
    if j + 1 < l1:
        am = max(am, abs(w[i, j + 1, k]))
    if k > 0:
        am = max(am, abs(w[i, j, k - 1]))
    if k + 1 < l2:
        am = max(am, abs(w[i, j, k + 1]))
    return _b7(abs(w[i, j, k])), _b7((n + 1) // 2), _b7(am)


@njit(cache=True, nogil=True)
def _hpred(w, i, j, k, l0, l1, l2, sb):
    """Prediction of a single-axis S-transform detail from the lowpass slope, ``(L[+1] - L[-1] + 2) >> 2``
    (S+P-style; 0 for the mixed subbands). A linear ramp of slope g has L[+1] - L[-1] = 4g and detail g."""
    if sb == 1:
        lm = w[i - 1, j, k] if i > 0 else w[i, j, k]
        lp = w[i + 1, j, k] if i + 1 < l0 else w[i, j, k]
    elif sb == 2:
        lm = w[i, j - 1, k] if j > 0 else w[i, j, k]
        lp = w[i, j + 1, k] if j + 1 < l1 else w[i, j, k]
    elif sb == 4:
        lm = w[i, j, k - 1] if k > 0 else w[i, j, k]
        lp = w[i, j, k + 1] if k + 1 < l2 else w[i, j, k]
    else:
        return np.int64(0)
    return (np.int64(lp) - np.int64(lm) + 2) >> 2


@njit(cache=True, nogil=True)
def _hdetail(w, i, j, k, l0, l1, l2, sb, lb, nb, cnt):
    """Prediction, its size bucket and the zero-flag context of detail ``sb`` of block (i, j, k)."""
    pr = _hpred(w, i, j, k, l0, l1, l2, sb)
    pb = min(_b7(abs(pr)), 2)
    return pr, pb, _HB_ZERO + (((sb * _NB7 + lb) * _NB7 + nb) * 3 + min(cnt, 2)) * 3 + pb


@njit(cache=True, nogil=True)
def _haar_any(w, n0, n1, n2):
    l0 = (n0 + 1) // 2
    l1 = (n1 + 1) // 2
    l2 = (n2 + 1) // 2
    for i in range(n0):
        for j in range(n1):
            for k in range(n2):
                if (i >= l0 or j >= l1 or k >= l2) and w[i, j, k] != 0:
                    return True
    return False


@njit(cache=True, nogil=True)
def encode_haar_arith(w, n0, n1, n2, out, base):
    """Adaptive binary arithmetic coding of the details of an S-transform tile (lossless files; the lowpass
    ``w[:l0, :l1, :l2]`` is known to the decoder) into ``out[base:]``; returns the byte count (0 = all zero).

    Block-interleaved order: the lowpass positions p (x slowest, z fastest); per p one flag "any of the (up to) 7
    details of this 2x2x2 block non-zero" -- the significance map at block granularity, so empty space costs a few
    thousandths of a bit per voxel -- then the details of the subbands b = 1..7 at p: each as the residual
    r = d - pred (:func:`_hpred`) with zero flag, sign, unary bit length and mantissa (top bit modelled, the rest
    raw). Contexts: the block's lowpass magnitude, the detail magnitudes of the three causal neighbour blocks, the
    largest lowpass magnitude of the six face neighbours (non-causal: the lowpass is known), the subband, the
    number of non-zero details already coded in the block, the prediction's size and sign. It codes S-transform
    tiles in fewer bits than the subband coder of :func:`encode_arith` (docs/bench/docstring-figures.md)."""
    if not _haar_any(w, n0, n1, n2):
        return 0
    l0 = (n0 + 1) // 2
    l1 = (n1 + 1) // 2
    l2 = (n2 + 1) // 2
    h0 = n0 // 2
    h1 = n1 // 2
    h2 = n2 // 2
    probs = np.full(N_HPROBS, _PTOT // 2, np.int64)
    st = _enc_init(base)
    for i in range(l0):
        for j in range(l1):
            for k in range(l2):
                lb, nb, ab = _hblock(w, i, j, k, l0, l1, l2, h0, h1, h2)
                anyd = 0
                for sb in range(1, 8):
                    if not _hhas(i, j, k, h0, h1, h2, sb):
                        continue
                    if w[_hat(i, j, k, l0, l1, l2, sb)] != 0:
                        anyd = 1
                        break
                _enc_bit(st, out, probs, _HB_BLOCK + (lb * _NB7 + nb) * _NB7 + ab, anyd)
                if not anyd:
                    continue
                cnt = 0
                inb = 0
                for sb in range(1, 8):
                    if not _hhas(i, j, k, h0, h1, h2, sb):
                        continue
                    pr, pb, ctx = _hdetail(w, i, j, k, l0, l1, l2, sb, lb, nb, cnt)
                    v = np.int64(w[_hat(i, j, k, l0, l1, l2, sb)]) - pr
                    if v == 0:
                        _enc_bit(st, out, probs, ctx, 0)
                        continue
                    _enc_bit(st, out, probs, ctx, 1)
                    cnt += 1
                    m = abs(v)
                    _enc_bit(st, out, probs, _hsign_ctx(sb, lb, pr), 1 if v < 0 else 0)
                    ectx = _hexp_ctx(sb, lb, nb, inb, pb)
                    inb += m
                    _enc_magnitude(st, out, probs, ectx, _HB_MAN + sb * 32, m)
    for _ in range(5):
        _shift_low(st, out)
    return st[4] - base


@njit(cache=True, nogil=True)
def decode_haar_arith(buf, base, length, w, n0, n1, n2):
    """Inverse of :func:`encode_haar_arith`: the lowpass must be in ``w`` already; returns 0 (or -1 on an
    inconsistent stream)."""
    l0 = (n0 + 1) // 2
    l1 = (n1 + 1) // 2
    l2 = (n2 + 1) // 2
    h0 = n0 // 2
    h1 = n1 // 2
    h2 = n2 // 2
    for i in range(n0):  # all details zero first (the stripped case, and the blocks flagged empty)
        for j in range(n1):
            for k in range(n2):
                if i >= l0 or j >= l1 or k >= l2:
                    w[i, j, k] = 0
    if length == 0:
        return 0
    if length < 5:
        return -1
    probs = np.full(N_HPROBS, _PTOT // 2, np.int64)
    st = _dec_init(buf, base, length)
    for i in range(l0):
        for j in range(l1):
            for k in range(l2):
                lb, nb, ab = _hblock(w, i, j, k, l0, l1, l2, h0, h1, h2)
                if _dec_bit(st, buf, probs, _HB_BLOCK + (lb * _NB7 + nb) * _NB7 + ab) == 0:
                    continue
                cnt = 0
                inb = 0
                for sb in range(1, 8):
                    if not _hhas(i, j, k, h0, h1, h2, sb):
                        continue
                    pr, pb, ctx = _hdetail(w, i, j, k, l0, l1, l2, sb, lb, nb, cnt)
                    v = np.int64(0)
                    if _dec_bit(st, buf, probs, ctx) == 1:
                        cnt += 1
                        neg = _dec_bit(st, buf, probs, _hsign_ctx(sb, lb, pr))
                        ectx = _hexp_ctx(sb, lb, nb, inb, pb)
                        m = _dec_magnitude(st, buf, probs, ectx, _HB_MAN + sb * 32)
                        if m < 0:
                            return -1
                        inb += m
                        v = -m if neg else m
                    w[_hat(i, j, k, l0, l1, l2, sb)] = v + pr
    if st[2] > st[3] + 4:
        return -1
    return 0
