"""Threads, the GIL and Ctrl-C."""

import os
import signal
import threading
import time

import numpy as np
import pytest

import tessera
from conftest import random_points, sigint_after


def arrays_of(result, names):
    return {n: np.array(getattr(result, n)) for n in names}


def test_threads_1_and_2_give_identical_results():
    pts = random_points(20000, 3, seed=6)
    labels = (pts[:, 2] > 0.5).astype(int)
    names = ["generators", "volumes", "centroids", "neighbor_offsets", "neighbors", "vertices", "vertex_keys",
             "cell_face_offsets", "face_vertex_offsets", "face_vertices", "face_neighbor", "face_class"]
    one = tessera.voronoi(pts, labels=labels, threads=1)
    two = tessera.voronoi(pts, labels=labels, threads=2)
    assert (one.threads_used, two.threads_used) == (1, 2)
    a, b = arrays_of(one, names), arrays_of(two, names)
    for n in names:
        assert a[n].dtype == b[n].dtype and a[n].tobytes() == b[n].tobytes(), n
    d1 = tessera.delaunay(pts, threads=1)
    d2 = tessera.delaunay(pts, threads=2)
    assert d1.simplices.tobytes() == d2.simplices.tobytes()


def test_more_threads_than_cores_run_as_asked(capfd):
    pts = random_points(3000, 3, seed=8)
    many = len(os.sched_getaffinity(0)) + 2
    one = tessera.voronoi(pts, threads=1)
    lots = tessera.voronoi(pts, threads=many)
    assert lots.threads_used == many
    assert np.array(one.neighbors).tobytes() == np.array(lots.neighbors).tobytes()
    assert np.array(one.vertices).tobytes() == np.array(lots.vertices).tobytes()
    assert "TBB" not in capfd.readouterr().err  # oneTBB's "number of workers is limited" warning
    with pytest.raises(ValueError, match="threads must be at most 4096, got 5000"):
        tessera.voronoi(pts, threads=5000)


def test_tessera_num_threads_is_respected(monkeypatch):
    pts = random_points(2000, 2)
    monkeypatch.setenv("TESSERA_NUM_THREADS", "1")
    assert tessera.voronoi(pts).threads_used == 1
    monkeypatch.setenv("TESSERA_NUM_THREADS", "2")
    assert tessera.voronoi(pts).threads_used == 2
    assert tessera.delaunay(pts).threads_used == 2
    assert tessera.voronoi(pts, threads=1).threads_used == 1  # the argument wins
    monkeypatch.setenv("TESSERA_NUM_THREADS", "lots")
    with pytest.raises(ValueError, match="TESSERA_NUM_THREADS must be an integer from 1 to 4096, got 'lots'"):
        tessera.voronoi(pts)


def test_the_gil_is_released_during_a_long_call():
    pts = random_points(300_000, 2, seed=1)
    stamps = []
    stop = threading.Event()

    def spin():  # a pure-Python thread: it runs only while nobody holds the GIL
        while not stop.is_set():
            stamps.append(time.perf_counter())
            for _ in range(100):
                pass

    t = threading.Thread(target=spin)
    t.start()
    try:
        t0 = time.perf_counter()
        tessera.voronoi(pts, threads=1)
        t1 = time.perf_counter()
    finally:
        stop.set()
        t.join()
    assert t1 - t0 > 0.1, "the call must be long enough to tell"
    # Had the call held the GIL, the other thread could not have run at all
    # between shortly after the call started and shortly before it returned.
    margin = 0.2 * (t1 - t0)
    during = [s for s in stamps if t0 + margin < s < t1 - margin]
    assert len(during) > 100


class Interrupted(Exception):
    pass


@pytest.mark.parametrize("func", [tessera.voronoi, tessera.delaunay])
def test_ctrl_c_interrupts_a_long_call(func):
    """SIGINT during a run: the run stops between batches and the exception the
    signal handler raised comes back (KeyboardInterrupt with Python's default
    handler; a custom one here, so that a signal arriving late could never
    stop the whole test session)."""
    pts = random_points(300_000, 3, seed=2)  # several seconds on one thread

    def handler(signum, frame):
        raise Interrupted()

    with sigint_after(0.3, handler):
        t0 = time.perf_counter()
        with pytest.raises(Interrupted):
            func(pts, threads=1)
        elapsed = time.perf_counter() - t0
    assert elapsed < 3.0  # stopped soon after the signal, not at the end
    assert tessera.voronoi(pts[:1000], threads=1).n_cells == 1000  # usable afterwards


def test_ctrl_c_interrupts_find_simplex():
    """The calls outside the engine check too (between chunks of queries):
    find_simplex on 15M queries ran 51 s past Ctrl-C."""
    dt = tessera.delaunay(random_points(200_000, 3, seed=4), threads=1)
    queries = random_points(4_000_000, 3, seed=5)  # ~6.5 s on one thread, uninterrupted

    def handler(signum, frame):
        raise Interrupted()

    dt.find_simplex(queries[:10])  # the locator is built before the clock starts
    with sigint_after(0.3, handler):
        t0 = time.perf_counter()
        with pytest.raises(Interrupted):
            dt.find_simplex(queries)
        elapsed = time.perf_counter() - t0
    assert elapsed < 2.0
    assert np.array_equal(dt.find_simplex(queries[:1000]), tessera.delaunay(dt.points).find_simplex(queries[:1000]))


def test_ctrl_c_interrupts_transform(monkeypatch):
    """transform is computed in blocks, with Ctrl-C taken between them: one
    batched numpy call ran 7 s at 1M points past it. Python takes a signal
    only between such calls, so what is checked is that no numpy call gets
    more than a block (the latency, which a timing bound could not show
    reliably on a loaded machine), that Ctrl-C raises, that nothing is kept,
    and that the next use computes the whole of it."""
    pts = random_points(200_000, 3, seed=6)
    whole = tessera.delaunay(pts, threads=1).transform
    assert len(whole) > 4 * 65_536
    sizes = []
    inv = np.linalg.inv

    def counting_inv(m):
        sizes.append(len(m))
        return inv(m)

    monkeypatch.setattr(np.linalg, "inv", counting_inv)
    dt = tessera.delaunay(pts, threads=1)
    assert np.array_equal(dt.transform, whole, equal_nan=True)
    assert len(sizes) > 4 and max(sizes) <= 65_536
    monkeypatch.undo()

    def handler(signum, frame):
        raise Interrupted()

    dt = tessera.delaunay(pts, threads=1)
    with sigint_after(0.05, handler):
        with pytest.raises(Interrupted):
            dt.transform
    assert np.array_equal(dt.transform, whole, equal_nan=True)


def test_ctrl_c_with_the_default_handler_raises_keyboard_interrupt():
    pts = random_points(300_000, 3, seed=3)
    with sigint_after(0.3, signal.default_int_handler):
        with pytest.raises(KeyboardInterrupt):
            tessera.voronoi(pts, threads=1)


def test_calls_from_other_threads_run_concurrently():
    pts = random_points(20000, 3)
    results = [None, None]

    def work(k):
        results[k] = tessera.voronoi(pts, threads=1).volumes.copy()

    threads = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert np.array_equal(results[0], results[1])


def test_concurrent_calls_of_any_thread_count_give_the_serial_results():
    # Python threads each running cells and Delaunay with 1, 2 or more threads
    # than cores (each such call raises oneTBB's worker cap while it runs):
    # every result equals the one-thread call's, bit for bit.
    rng = np.random.default_rng(5)
    inputs = [(rng.random((8000, 3)), None), (rng.random((12000, 2)), rng.integers(-1, 3, 12000)),
              (rng.random((6000, 3)) ** 3, None)]
    many = len(os.sched_getaffinity(0)) + 1

    def run(i, threads):
        pts, labels = inputs[i]
        v = tessera.voronoi(pts, labels=labels, threads=threads)
        out = [np.array(v.neighbors).tobytes(), np.array(v.volumes).tobytes(), np.array(v.vertices).tobytes()]
        if labels is None:
            out.append(np.array(tessera.delaunay(pts, threads=threads).simplices).tobytes())
        return out

    serial = [run(i, 1) for i in range(len(inputs))]
    got = {}

    def work(k):
        for rep in range(2):
            i = (k + rep) % len(inputs)
            got[(k, rep)] = (i, run(i, (1, 2, many)[k % 3]))

    threads = [threading.Thread(target=work, args=(k,)) for k in range(6)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(got) == 12
    for (k, rep), (i, r) in got.items():
        assert r == serial[i], (k, rep, i)
