"""Memory and threads of evaluation (issue 13, item 11b): a pumped BRDF with broadcast inputs works
in blocks, the input checks work in blocks, and threads that evaluate one freshly made pumped
object give exactly the serial values."""

import threading
import tracemalloc

import numpy as np

import pumpup
from pumpup.core import as_directions


def hemisphere(rng, n):
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    d[:, 2] = np.abs(d[:, 2])
    return d


def peak_bytes(fn):
    tracemalloc.start()
    tracemalloc.reset_peak()
    try:
        result = fn()
        return result, tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_pumped_eval_of_broadcast_inputs_works_in_blocks():
    rng = np.random.default_rng(11)
    p = pumpup.pump({"type": "phong", "n": 20}, g="g2")
    wi, wo = hemisphere(rng, 1500), hemisphere(rng, 1600)
    p.eval(wi[:5], wo[:5])  # tables and compiled kernels first
    out, peak = peak_bytes(lambda: p.eval(wi[:, None, :], wo[None, :, :]))
    assert out.shape == (1500, 1600)
    size = out.nbytes  # 19 MB; both directions copied would be 2 x 58 MB more
    assert peak < 1.5 * size, (peak, size)
    # the same numbers as pair by pair on explicit copies
    k = rng.integers(0, 1500, 200), rng.integers(0, 1600, 200)
    np.testing.assert_array_equal(out[k], p.eval(wi[k[0]], wo[k[1]]))
    np.testing.assert_allclose(out[k], p.reference(wi[k[0]], wo[k[1]]), rtol=1e-12)


def test_input_checks_work_in_blocks():
    rng = np.random.default_rng(2)
    d = hemisphere(rng, 2_000_000)  # 48 MB
    _, peak = peak_bytes(lambda: as_directions(d, "wi"))
    assert peak < 4e6, peak  # the whole-array check made 16 + 6 + 2 + 16 MB of temporaries
    bad = d.copy()
    bad[1_234_567, 1] = 2.0
    try:
        as_directions(bad, "wi")
    except ValueError as exc:
        assert "wi[1234567]" in str(exc)
    else:
        raise AssertionError("a non-unit direction passed")


def test_threads_on_a_fresh_pumped_object_are_bit_identical_to_serial():
    rng = np.random.default_rng(8)
    wi, wo = hemisphere(rng, 20000), hemisphere(rng, 20000)
    spec = {"type": "pumped", "base": {"type": "phong", "n": 20}, "g": "g2", "levels": 2}
    serial = pumpup.load(spec).eval(wi, wo)  # builds and caches the tables
    for trial in range(4):
        fresh = pumpup.load(spec)  # tables cached, its look-ups not yet built
        barrier = threading.Barrier(8)
        results = [None] * 8

        def work(k):
            barrier.wait()
            results[k] = fresh.eval(wi, wo)

        threads = [threading.Thread(target=work, args=(k,)) for k in range(8)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        for r in results:
            np.testing.assert_array_equal(r, serial)
