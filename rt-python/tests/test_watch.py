"""What a render tells its caller besides the image: the optics it chose
(repeatable across a time series), progress while it runs, Ctrl-C, and a
MemoryError instead of an abort when the image cannot fit."""

import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import rtvis
from helpers import bump


def test_chosen_optics_repeat_the_render_on_other_data():
    vol, _, _ = bump(n=32, delta=1e-4)
    strong, _, _ = bump(n=32, delta=2e-4)
    for render in (rtvis.schlieren, rtvis.shadowgraph, rtvis.color_schlieren):
        kw = dict(size=48, photons=4)
        img, chosen = render(vol, chosen=True, **kw)
        assert isinstance(chosen, rtvis.Optics)
        # The same data and the chosen optics: the same image, bit for bit.
        assert np.array_equal(render(vol, **chosen), img), render.__name__
        # Another time step with the first one's optics differs from its
        # own automatic choice, which spends the range on the stronger flow.
        fixed, auto = render(strong, **chosen), render(strong, **kw)
        assert not np.array_equal(fixed, auto), render.__name__
        contrast = [float(np.abs(i - 1).mean()) for i in (fixed, auto)]
        assert contrast[0] > 1.5 * contrast[1], (render.__name__, contrast)
    _, chosen = rtvis.schlieren(vol, size=32, photons=4, angle=30.0, chosen=True)
    assert set(chosen) == {"cutoff", "angle", "f", "h", "film_distance", "axis", "size", "photons",
                           "seed", "estimator"}
    assert chosen.cutoff == "knife" and chosen.angle == 30.0 and chosen.h > 0
    assert chosen.description.startswith("knife edge at 30.0°")
    _, chosen = rtvis.shadowgraph(vol, size=32, photons=4, chosen=True)
    assert set(chosen) == {"distance", "axis", "size", "photons", "seed"} and chosen.distance > 0
    _, chosen = rtvis.interferogram(vol, size=32, photons=4, chosen=True)
    assert chosen["wavelength"] == 10.6e-6 and chosen["fringe_spacing"] is None
    with pytest.raises(AttributeError, match="no field 'radius'"):
        chosen.radius
    # The tuple grows at its end only.
    img, eps, phi, chosen = rtvis.interferogram(vol, size=32, photons=4, deflection=True, phase=True,
                                                chosen=True)
    assert img.shape == (32, 32) and eps.shape == (32, 32, 2) and phi.shape == (32, 32)


def test_bos_and_focusing_return_the_rig_they_chose():
    vol, _, _ = bump(n=32, delta=1e-4)
    *images, info, chosen = rtvis.bos(vol, size=32, chosen=True)
    assert isinstance(chosen, rtvis.Optics) and chosen.description == info
    assert {"focal_length", "pixel", "distance", "background_distance"} <= set(chosen)
    again = rtvis.bos(vol, **chosen)
    assert all(np.array_equal(a, b) for a, b in zip(images, again[:3]))
    *images, info, chosen = rtvis.focusing(vol, size=32, samples=2, chosen=True)
    assert chosen.pitch > 0 and chosen.aperture > 0
    again = rtvis.focusing(vol, **chosen)
    assert all(np.array_equal(a, b) for a, b in zip(images, again[:3]))


def test_progress_is_reported_on_the_calling_thread_up_to_the_total(capsys):
    import threading

    vol, _, _ = bump(n=32)
    seen = []
    me = threading.get_ident()

    def progress(done, total):
        assert threading.get_ident() == me
        seen.append((done, total))

    img = rtvis.schlieren(vol, size=64, photons=16, progress=progress)
    assert seen and seen[-1][0] == seen[-1][1] == 64 * 64 * 16
    assert all(a[0] < b[0] for a, b in zip(seen, seen[1:])), "each count once"
    # Progress does not change the image.
    assert np.array_equal(img, rtvis.schlieren(vol, size=64, photons=16))
    rtvis.shadowgraph(vol, size=32, photons=4, progress=True)
    assert capsys.readouterr().err.count("rtvis.shadowgraph 100% |") == 1
    scene = rtvis.Scene().add_spheres(np.zeros((1, 3), np.float32), radii=1.0)
    tiles = []
    scene.render(size=64, passes=3, progress=lambda d, t: tiles.append((d, t)))
    assert tiles[-1][0] == tiles[-1][1] and tiles[-1][1] % 3 == 0
    with pytest.raises(TypeError, match="progress"):
        rtvis.schlieren(vol, size=16, progress="yes")
    # BOS and focusing count rays: width × height × samples².
    for render, kw, k in ((rtvis.bos, dict(samples=3), 3), (rtvis.focusing, dict(samples=2), 2)):
        rays = []
        image = render(vol, size=40, progress=lambda d, t: rays.append((d, t)), **kw)[0]
        assert rays[-1] == (image.size * k * k,) * 2, (render.__name__, rays[-1])
        assert all(a[0] < b[0] for a, b in zip(rays, rays[1:]))


def test_an_exception_in_the_progress_callback_stops_the_render():
    vol, _, _ = bump(n=32)
    calls = []

    def fail(done, total):
        calls.append(done)
        raise RuntimeError("enough")

    with pytest.raises(RuntimeError, match="enough"):
        rtvis.schlieren(vol, size=512, photons=64, progress=fail)
    assert len(calls) == 1
    # The next render runs normally.
    assert rtvis.schlieren(vol, size=16, photons=4).shape == (16, 16)


def run_python(code, timeout=300, **kw):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    return subprocess.Popen([sys.executable, "-c", textwrap.dedent(code)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env, **kw)


@pytest.mark.parametrize("what", ["schlieren", "bos", "surface"])
def test_ctrl_c_interrupts_a_long_render(what):
    # Renders that take minutes uninterrupted; SIGINT once each is under
    # way must end them with KeyboardInterrupt, the process alive to
    # report it and to render again.
    code = f"""
        import sys, time
        import numpy as np
        sys.path.insert(0, {os.path.dirname(__file__)!r})
        import rtvis
        from helpers import bump
        vol, _, _ = bump(n=48)
        print("ready", flush=True)
        t = time.monotonic()
        try:
            if {what!r} == "schlieren":
                rtvis.schlieren(vol, size=4096, photons=1024)
            elif {what!r} == "bos":
                rtvis.bos(vol, size=4096, samples=32)
            else:
                s = rtvis.Scene().add_spheres(np.random.default_rng(1).random((20000, 3), np.float32), radii=0.01)
                s.render(size=2048, passes=4000, ao=16)
        except KeyboardInterrupt:
            print("interrupted", time.monotonic() - t, flush=True)
            print("again", rtvis.schlieren(vol, size=16, photons=4).shape, flush=True)
    """
    p = run_python(code)
    assert p.stdout.readline().strip() == "ready"
    time.sleep(2.0)
    sent = time.monotonic()
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=120)
    took = time.monotonic() - sent
    assert p.returncode == 0, err
    assert "interrupted" in out and "again (16, 16)" in out, out + err
    # Uninterrupted, each render runs for minutes; stopping takes a poll
    # (50 ms) and a photon, ray or tile.
    assert took < 20.0, f"{took:.1f} s after SIGINT"


def test_a_film_that_cannot_fit_is_a_memory_error_not_an_abort():
    # An address-space limit far below the 15 GB a 16384² film takes.
    code = """
        import resource, sys
        import numpy as np
        sys.path.insert(0, %r)
        import rtvis
        from helpers import bump
        vol, _, _ = bump(n=32)
        resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))
        for what in ("schlieren", "surface"):
            try:
                if what == "schlieren":
                    rtvis.schlieren(vol, size=16384, photons=4)
                else:
                    rtvis.Scene().add_spheres(np.zeros((1, 3), np.float32), radii=1.0).render(size=16384)
            except MemoryError as e:
                print(what, "MemoryError:", e, flush=True)
        print("still", rtvis.schlieren(vol, size=32, photons=4).shape, flush=True)
    """ % os.path.dirname(__file__)
    p = run_python(code)
    out, err = p.communicate(timeout=300)
    assert p.returncode == 0, err
    assert "schlieren MemoryError: rtvis: the film's" in out, out + err
    assert "surface MemoryError:" in out, out + err
    assert "still (32, 32)" in out
