#!/usr/bin/env python3
"""Renders the built documentation site in headless Chromium and checks that it shows (ctest
docs.render): a broken theme or an empty page fails.

  1. builds the site (tools/build_docs.sh) when build/site/index.html is missing, or with --build;
  2. serves build/site on a free loopback port (python -m http.server in a subprocess);
  3. for the front page and reference/configuration/:
     - the HTML: served (200), its <title> holds the page's title (site_name for the front page,
       its nav title in mkdocs.yml for the others), its article has the page's first heading and
       some text after it, and the theme's stylesheet it links is served;
     - a screenshot (chromium --headless, 1280 x 1600) into --out (front.png, reference-configuration.png):
       not blank (pixel spread, a share of the pixels unlike the background), and the header band
       at the top in one colour that is not the background's (the theme's bar: without its
       stylesheet the page is black text on white).

  tools/check_docs_render.py [--out DIR] [--build]

Runs under .venv's Python (matplotlib reads the PNGs; re-executes itself there). Exit status 77
(ctest: skipped) without Chromium, without .venv, or without doxygen / mkdocs for a build.
"""

import argparse
import html
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SITE = os.path.join(ROOT, "build", "site")
VENV_PYTHON = os.path.join(ROOT, ".venv", "bin", "python")
WIDTH, HEIGHT = 1280, 1600
# (URL path in the site, source page under docs/, screenshot name)
PAGES = [
    ("", "index.md", "front"),
    ("reference/configuration/", "reference/configuration.md", "reference-configuration"),
]
# On a closed network every request to the outside must fail at once rather than wait: the
# background services are off, and host names other than the loopback resolve to nothing (the
# theme's web fonts then fall back to the system's at once).
CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
    "--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE 127.0.0.1",
]
CHROMIUM_TIMEOUT_S = 120.0
# A page shows when its pixels spread (grey-level standard deviation) and a share of them differ
# from the background; the theme shows when the top band is mostly one colour unlike it.
MIN_GREY_STD = 0.02
MIN_SHARE_UNLIKE_BACKGROUND = 0.02
HEADER_ROWS = 40
MIN_HEADER_SHARE = 0.6
MIN_COLOUR_DIFFERENCE = 0.12
MIN_ARTICLE_CHARS = 20


def skip(message):
    print(f"check_docs_render: {message} (skipped)")
    sys.exit(77)


def fail(message):
    print(f"check_docs_render: FAILED: {message}", file=sys.stderr)
    sys.exit(1)


def ensure_venv():
    try:
        import matplotlib  # noqa: F401
        import yaml  # noqa: F401
    except ImportError:
        if os.path.exists(VENV_PYTHON) and os.path.realpath(sys.prefix) != os.path.realpath(
            os.path.join(ROOT, ".venv")
        ):
            os.execv(VENV_PYTHON, [VENV_PYTHON] + sys.argv)
        skip("no .venv with matplotlib and mkdocs: run tools/setup_venv.sh")


def expected_titles():
    """{source page: the title its <title> must hold}: site_name for the front page, else the
    nav title of mkdocs.yml (the page's first heading when the nav gives none)."""
    import yaml

    class Loader(yaml.SafeLoader):
        pass

    Loader.add_multi_constructor("", lambda loader, suffix, node: None)  # !!python/name: and the like
    with open(os.path.join(ROOT, "mkdocs.yml"), encoding="utf-8") as f:
        config = yaml.load(f, Loader=Loader)
    titles = {"index.md": config["site_name"]}

    def walk(items):
        for item in items or []:
            if isinstance(item, dict):
                for title, value in item.items():
                    if isinstance(value, str):
                        titles.setdefault(value, title)
                    else:
                        walk(value)

    walk(config.get("nav"))
    return titles


def first_heading(source):
    """The plain text of a Markdown page's first heading, or None."""
    with open(source, encoding="utf-8") as f:
        text = f.read()
    text = re.sub(r"\A---\n.*?\n---\n", "", text, flags=re.S)  # front matter
    text = re.sub(r"^(```|~~~).*?^\1", "", text, flags=re.S | re.M)  # code blocks
    m = re.search(r"^#{1,6}[ \t]+(.+?)[ \t#]*$", text, re.M)
    if not m:
        return None
    heading = re.sub(r"\{[^}]*\}\s*$", "", m.group(1))  # attr_list
    heading = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # links
    return " ".join(re.sub(r"[`*_]", "", heading).split())


def plain(fragment):
    fragment = re.sub(r"<a class=\"headerlink\".*?</a>", "", fragment, flags=re.S)
    return " ".join(html.unescape(re.sub(r"<[^>]+>", " ", fragment)).split())


class Server:
    """python -m http.server on a free loopback port, serving build/site."""

    def __init__(self, log_path):
        self.log = open(log_path, "w")
        self.proc = subprocess.Popen(
            [sys.executable, "-u", "-m", "http.server", "0", "--bind", "127.0.0.1", "--directory", SITE],
            stdout=subprocess.PIPE,
            stderr=self.log,
            text=True,
        )
        line = []
        reader = threading.Thread(target=lambda: line.append(self.proc.stdout.readline()), daemon=True)
        reader.start()
        reader.join(15.0)
        m = re.search(r"port (\d+)", line[0]) if line else None
        if not m:
            self.stop()
            fail(f"python -m http.server did not start (log: {log_path})")
        self.url = f"http://127.0.0.1:{m.group(1)}/"

    def get(self, path):
        try:
            with urllib.request.urlopen(self.url + path, timeout=10) as response:
                return response.status, response.read()
        except urllib.error.HTTPError as e:
            return e.code, b""

    def stop(self):
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self.log.close()


def check_html(server, path, source, title):
    """Checks the served HTML of one page; returns a line for the report."""
    status, body = server.get(path)
    if status != 200:
        fail(f"/{path}: HTTP {status}")
    page = body.decode("utf-8", "replace")
    m = re.search(r"<title>(.*?)</title>", page, re.S)
    shown = plain(m.group(1)) if m else ""
    if title not in shown:
        fail(f"/{path}: <title> is {shown!r}, without the page's title {title!r}")
    m = re.search(r"<article\b[^>]*>(.*?)</article>", page, re.S)
    if not m:
        fail(f"/{path}: no <article>: not a page of the theme")
    article = m.group(1)
    heading = first_heading(os.path.join(ROOT, "docs", source))
    h1 = re.search(r"<h1\b[^>]*>(.*?)</h1>", article, re.S)
    if heading is not None and (not h1 or plain(h1.group(1)) != heading):
        fail(f"/{path}: the article's h1 is {plain(h1.group(1)) if h1 else None!r}, not {heading!r} ({source})")
    text = plain(article[h1.end() :] if h1 else article)
    if len(text) < MIN_ARTICLE_CHARS:
        fail(f"/{path}: the article is empty ({text!r})")
    css = re.findall(r"<link rel=\"stylesheet\" href=\"([^\"]*assets/stylesheets/main\.[^\"]*\.css)\"", page)
    if not css:
        fail(f"/{path}: links no theme stylesheet (assets/stylesheets/main.*.css)")
    css_path = os.path.normpath(os.path.join(os.path.dirname("/" + path + "x"), css[0])).lstrip("/")
    status, sheet = server.get(css_path)
    if status != 200 or len(sheet) < 10000:
        fail(f"/{path}: the theme's stylesheet /{css_path} is not served (HTTP {status}, {len(sheet)} bytes)")
    return f"title {title!r}, h1 {heading!r}, {len(text)} characters of text, theme stylesheet served"


def screenshot(chromium, url, png, log_path):
    with tempfile.TemporaryDirectory(prefix="pmstep-chromium-") as profile, open(log_path, "w") as log:
        command = (
            [chromium]
            + CHROMIUM_FLAGS
            + [f"--user-data-dir={profile}", f"--screenshot={png}", f"--window-size={WIDTH},{HEIGHT}", url]
        )
        log.write(" ".join(command) + "\n")
        log.flush()
        proc = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=log, stderr=log, start_new_session=True)
        try:
            rc = proc.wait(timeout=CHROMIUM_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
            fail(f"chromium took over {CHROMIUM_TIMEOUT_S:.0f} s for {url} (log: {log_path})")
    if rc != 0 or not os.path.exists(png):
        with open(log_path, errors="replace") as f:
            tail = "".join(f.readlines()[-15:])
        fail(f"chromium exit code {rc}, no {png}:\n{tail}")


def check_png(png):
    """Checks one screenshot is not blank and shows the theme's bar; returns a line for the report."""
    import matplotlib.image
    import numpy as np

    image = matplotlib.image.imread(png)
    if image.dtype != np.float32 and image.dtype != np.float64:
        image = image / 255.0
    rgb = image[..., :3]
    if rgb.shape[:2] != (HEIGHT, WIDTH):
        fail(f"{png}: {rgb.shape[1]} x {rgb.shape[0]} pixels, not {WIDTH} x {HEIGHT}")

    def mode_colour(pixels):
        codes = np.round(pixels.reshape(-1, 3) * 255).astype(np.int32)
        packed = (codes[:, 0] << 16) | (codes[:, 1] << 8) | codes[:, 2]
        values, counts = np.unique(packed, return_counts=True)
        top = values[np.argmax(counts)]
        return np.array([(top >> 16) & 255, (top >> 8) & 255, top & 255]) / 255.0, counts.max() / packed.size

    def unlike(pixels, colour):
        return np.abs(pixels - colour).max(axis=-1) > MIN_COLOUR_DIFFERENCE

    def hex_colour(colour):
        return "#" + "".join(f"{round(c * 255):02x}" for c in colour)

    grey_std = float(rgb.mean(axis=-1).std())
    background, _ = mode_colour(rgb)
    share = float(unlike(rgb, background).mean())
    if grey_std < MIN_GREY_STD or share < MIN_SHARE_UNLIKE_BACKGROUND:
        fail(
            f"{png} is blank: grey-level std {grey_std:.4f} (min {MIN_GREY_STD}), {100 * share:.2f} % of pixels "
            f"unlike the background {hex_colour(background)} (min {100 * MIN_SHARE_UNLIKE_BACKGROUND:.0f} %)"
        )
    header, header_share = mode_colour(rgb[:HEADER_ROWS])
    if header_share < MIN_HEADER_SHARE or not unlike(header, background):
        fail(
            f"{png}: no theme header bar: the top {HEADER_ROWS} rows are {100 * header_share:.0f} % "
            f"{hex_colour(header)}, background {hex_colour(background)} (the theme's stylesheet did not apply?)"
        )
    return (
        f"std {grey_std:.3f}, {100 * share:.1f} % of pixels unlike the background {hex_colour(background)}, "
        f"header bar {hex_colour(header)}"
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--out",
        default=os.path.join(ROOT, "build", "docs-render"),
        help="folder for the screenshots and logs (build/docs-render)",
    )
    parser.add_argument("--build", action="store_true", help="build the site first even if it exists")
    args = parser.parse_args()
    ensure_venv()
    chromium = next(
        (shutil.which(name) for name in ("chromium", "chromium-browser", "google-chrome") if shutil.which(name)), None
    )
    if chromium is None:
        skip("no chromium: run tools/install_deps.sh")

    started = time.monotonic()
    if args.build or not os.path.exists(os.path.join(SITE, "index.html")):
        rc = subprocess.call([os.path.join(ROOT, "tools", "build_docs.sh")], cwd=ROOT)
        if rc == 77:
            skip("the site cannot be built here")
        if rc != 0:
            fail(f"tools/build_docs.sh exit code {rc}")
    os.makedirs(args.out, exist_ok=True)
    titles = expected_titles()
    server = Server(os.path.join(args.out, "http.log"))
    try:
        for path, source, name in PAGES:
            if not os.path.exists(os.path.join(ROOT, "docs", source)):
                fail(f"docs/{source} is missing")
            title = titles.get(source) or first_heading(os.path.join(ROOT, "docs", source)) or ""
            report = check_html(server, path, source, title)
            print(f"/{path}: {report}")
            png = os.path.join(args.out, f"{name}.png")
            if os.path.exists(png):
                os.unlink(png)
            shot_started = time.monotonic()
            screenshot(chromium, server.url + path, png, os.path.join(args.out, f"{name}.chromium.log"))
            print(f"  {png} ({time.monotonic() - shot_started:.1f} s): {check_png(png)}")
    finally:
        server.stop()
    print(f"check_docs_render: {len(PAGES)} pages render ({time.monotonic() - started:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
