"""`rt serve` driven in a real browser (headless Chromium through
Playwright), as a user would: open the page for the built-in blast wave,
wait for an image, move the knife, paint a stroke, break a setting, save
the figure, close the tab.

Checks, each against something the page did not compute:
- the knife image the page shows is, pixel for pixel, what `rt schlieren`
  writes when run with the command line the page shows;
- the painted image is the filter the page painted (read back from its
  canvas) applied here, in numpy, to the deflections the server recorded;
- a bad setting is a message on the page and the server goes on;
- a closed tab stops the work (the server's CPU time stops growing).

Usage: python serve_browser.py RT_BINARY OUT_DIR  (screenshots and the
latencies land in OUT_DIR; needs /usr/bin/chromium, numpy, pillow,
playwright).
"""

import io
import json
import os
import shlex
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request

import numpy as np
from PIL import Image
from playwright.sync_api import sync_playwright

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DATA = os.path.join(ROOT, "rt-tools", "data", "blast_sedov_64.nhdr")
CHROMIUM_FLAGS = [
    "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
]


def srgb_to_linear(c):
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def linear_to_srgb(c):
    c = np.clip(c, 0.0, 1.0)
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1 / 2.4) - 0.055)


def cpu_seconds(pid):
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def main(rt, out):
    os.makedirs(out, exist_ok=True)
    saved = tempfile.mkdtemp(prefix="rt-serve-")
    server = subprocess.Popen(
        [rt, "serve", DATA, "--out", saved], stdout=subprocess.PIPE, text=True, cwd=ROOT
    )
    try:
        line = server.stdout.readline()
        assert line.startswith("rt serve: http://127.0.0.1:"), line
        url = line.split()[2]
        run(rt, url, out, saved, server.pid)
    finally:
        server.terminate()
        server.wait(timeout=10)


def state(page):
    return page.evaluate("() => ({...document.body.dataset})")


def wait_converged(page, after_generation, timeout=60):
    """Waits until the page has sent its settings (nothing pending) and
    shows the last pass of what it sent, a generation newer than
    `after_generation`; returns (seconds to the first pass, to the last,
    the generation)."""
    t0 = time.monotonic()
    first = None
    while time.monotonic() - t0 < timeout:
        s = page.evaluate("() => ({...document.body.dataset, busy: posting || repost})")
        posted = int(s.get("posted", 0) or 0)
        gen = int(s.get("generation", 0) or 0)
        if not s["busy"] and posted > after_generation and gen == posted:
            if s.get("shown") == s.get("serial"):
                if first is None:
                    first = time.monotonic() - t0
                if s.get("pass") == s.get("passes") and int(s.get("pass", 0) or 0) > 0:
                    return first or time.monotonic() - t0, time.monotonic() - t0, gen
        time.sleep(0.005)
    raise AssertionError(f"no converged image after {timeout} s: {state(page)}")


def shown_image(page):
    """The image the page shows, as the browser fetched it (RGB)."""
    data = page.evaluate(
        """async () => { const r = await fetch(document.getElementById('image').src);
        const b = new Uint8Array(await r.arrayBuffer()); return Array.from(b); }"""
    )
    return np.asarray(Image.open(io.BytesIO(bytes(data))).convert("RGB")).astype(int)


def run(rt, url, out, saved, pid):
    latencies = {}
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path="/usr/bin/chromium", args=CHROMIUM_FLAGS)
        page = browser.new_page(viewport={"width": 1280, "height": 940})
        page.goto(url)
        # The page's defaults (256 px, 16 photons a pixel): the latency of
        # a knife move, to the first refined image and to the converged.
        _, _, gen = wait_converged(page, 0)
        for angle in [30, 60]:
            page.eval_on_selector(
                "#angle", f"el => {{ el.value = {angle}; el.dispatchEvent(new Event('input')); }}"
            )
            first, last, gen = wait_converged(page, gen)
            latencies.setdefault("256 px, knife moved: first image", []).append(first)
            latencies.setdefault("256 px, knife moved: converged", []).append(last)
        page.eval_on_selector("#angle", "el => { el.value = 0; el.dispatchEvent(new Event('input')); }")
        page.fill("#size", "128")
        _, _, gen = wait_converged(page, gen)
        page.screenshot(path=os.path.join(out, "serve-1-knife.png"))
        knife0 = shown_image(page)

        # Move the knife: 90°, as a drag of the slider would.
        t = time.monotonic()
        page.eval_on_selector(
            "#angle", "el => { el.value = 90; el.dispatchEvent(new Event('input')); }"
        )
        first, last, gen = wait_converged(page, gen)
        latencies["128 px, knife moved: first image"] = [first]
        latencies["128 px, knife moved: converged"] = [last]
        page.screenshot(path=os.path.join(out, "serve-2-knife-90.png"))
        knife90 = shown_image(page)
        assert np.abs(knife90 - knife0).mean() > 1.0, "moving the knife changed nothing"
        # The command line the page shows, run here: the same image.
        command = page.inner_text("#command")
        words = shlex.split(command)
        assert words[:2] == ["rt", "schlieren"] and "--angle" in words, command
        cli = os.path.join(out, "cli-knife-90.png")
        subprocess.run([rt] + words[1:] + ["--no-figure", "--out", cli], check=True, cwd=ROOT)
        expected = np.asarray(Image.open(cli).convert("RGB")).astype(int)
        assert expected.shape == knife90.shape, (expected.shape, knife90.shape)
        assert np.abs(expected - knife90).max() == 0, "the page's knife image is not rt schlieren's"

        # Many quick changes: the newest state wins, nothing queues.
        for a in range(0, 60, 3):
            page.eval_on_selector(
                "#angle", f"el => {{ el.value = {a}; el.dispatchEvent(new Event('input')); }}"
            )
        _, _, gen = wait_converged(page, gen)
        assert "--angle 57" in page.inner_text("#command"), page.inner_text("#command")

        # Paint: the picking pass, then a black filter with one white stroke.
        page.check("#paint")
        _, _, gen = wait_converged(page, gen)
        page.click("button[data-preset=black]")
        box = page.locator("#filter").bounding_box()
        page.mouse.move(box["x"] + 0.62 * box["width"], box["y"] + 0.3 * box["height"])
        page.mouse.down()
        page.mouse.move(box["x"] + 0.85 * box["width"], box["y"] + 0.5 * box["height"], steps=8)
        page.mouse.up()
        page.wait_for_function("() => !sending && !again")
        frame = json.loads(urllib.request.urlopen(f"{url}api/frame?after=0").read())
        half_range = frame["half_range"]
        assert half_range and half_range > 0, frame
        filt = page.evaluate(
            """() => Array.from(document.getElementById('filter').getContext('2d')
            .getImageData(0, 0, 256, 256).data)"""
        )
        filt = np.asarray(filt, dtype=float).reshape(256, 256, 4)[..., :3] / 255.0
        try:
            raw = urllib.request.urlopen(f"{url}api/deflections.bin").read()
        except urllib.error.HTTPError as e:
            raise AssertionError(f"deflections: {e.read()!r}; frame {frame}") from e
        defl = np.frombuffer(raw, dtype="<f4").reshape(-1, 3).astype(float)
        light, eu, ev = defl[:, 0], defl[:, 1], defl[:, 2]
        size = 256
        i = np.floor((eu / half_range + 1) * 0.5 * size)
        j = np.floor((ev / half_range + 1) * 0.5 * size)
        inside = np.isfinite(i) & (i >= 0) & (j >= 0) & (i < size) & (j < size)
        ii, jj = np.where(inside, i, 0).astype(int), np.where(inside, j, 0).astype(int)
        transmit = srgb_to_linear(filt[size - 1 - jj, ii]) * inside[:, None]
        want = np.round(255 * linear_to_srgb(transmit * np.nan_to_num(light)[:, None]))
        deadline = time.monotonic() + 10
        while True:
            got = shown_image(page).reshape(-1, 3)
            if got.shape == want.shape and np.abs(got - want).max() <= 1:
                break
            if time.monotonic() > deadline:
                bad = np.abs(got - want).max(axis=1) > 1 if got.shape == want.shape else None
                raise AssertionError(
                    f"painted image is not the filter on the deflections: {got.shape} vs "
                    f"{want.shape}, {None if bad is None else bad.sum()} pixels off"
                )
            time.sleep(0.1)
        lit = (got.max(axis=1) > 128).mean()
        assert 0.001 < lit < 0.5, f"the stroke lit {lit:.3%} of the image"
        page.screenshot(path=os.path.join(out, "serve-3-painted.png"))

        # Save figure: the same figure `rt schlieren --figure` writes.
        page.click("#save")
        page.wait_for_function(
            "() => document.getElementById('saved').textContent.startsWith('wrote')",
            timeout=60000,
        )
        for name in ["painted.png", "painted-figure.png", "filter.png"]:
            assert os.path.getsize(os.path.join(saved, name)) > 0, name

        # A bad setting: a message on the page, and the server goes on.
        page.uncheck("#paint")
        page.fill("#size", "0")
        page.wait_for_function(
            "() => document.getElementById('message').textContent.includes('--size')"
        )
        page.screenshot(path=os.path.join(out, "serve-4-bad-size.png"))
        page.fill("#size", "96")
        _, _, gen = wait_converged(page, gen)
        assert page.inner_text("#message") == ""

        # A long render, then the tab closes: the work stops.
        page.fill("#photons", "65536")
        page.wait_for_timeout(1500)
        page.close()
        time.sleep(4.0)
        before = cpu_seconds(pid)
        time.sleep(2.0)
        spent = cpu_seconds(pid) - before
        assert spent < 0.2, f"the server spent {spent:.2f} CPU-s after the tab closed"
        browser.close()

    with open(os.path.join(out, "serve-latency.json"), "w") as f:
        json.dump(latencies, f, indent=1)
    for k, v in latencies.items():
        print(f"rt serve: {k}: " + ", ".join(f"{x * 1000:.0f}" for x in v) + " ms")
    print(f"rt serve: browser test passed; screenshots in {out}")


if __name__ == "__main__":
    main(os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2]))
