"""The documentation site: every page renders in headless Chromium and every gallery image loads.

``make test`` builds the site first (``make docs``: Sphinx with warnings as errors, the gallery
examples executed) and points ``ROCKSTUDY_DOCS_HTML`` at it; run alone, this test builds it.
"""

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import matplotlib.image as mpimg
import numpy as np
import pytest
from _helpers import chromium_dom

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "docs" / "examples").glob("plot_*.py"))


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    given = os.environ.get("ROCKSTUDY_DOCS_HTML")
    if given:
        html = Path(given)
        assert (html / "index.html").is_file(), f"ROCKSTUDY_DOCS_HTML={given} holds no built site"
        return html
    html = tmp_path_factory.mktemp("docs") / "html"
    subprocess.run(
        [
            sys.executable,
            "-m",
            "sphinx",
            "-W",
            "--keep-going",
            "-q",
            "-b",
            "html",
            str(ROOT / "docs"),
            str(html),
        ],
        check=True,
        timeout=1200,
    )
    return html


HARNESS = """<!doctype html><html><body><pre id="out">waiting</pre>
<iframe id="f" width="1280" height="1000"></iframe>
<script>
const pages = %s;
const rows = [];
let i = 0;
const f = document.getElementById("f");
f.onload = () => {
  const d = f.contentDocument;
  const imgs = [...d.querySelectorAll("img")];
  const bad = imgs.filter(im => !(im.complete && im.naturalWidth > 0)).map(im => im.src);
  const main = d.querySelector("main") || d.body;
  rows.push(JSON.stringify({page: pages[i], title: d.title, text: main.innerText.length,
                            images: imgs.length, broken: bad,
                            described: d.querySelectorAll("dl.py").length}));
  i += 1;
  if (i < pages.length) { f.src = pages[i]; }
  else { document.getElementById("out").textContent = "RESULTS\\n" + rows.join("\\n") + "\\nEND"; }
};
f.src = pages[0];
</script></body></html>
"""


def render_all(html, pages, workdir):
    harness = html / "_render_check.html"
    harness.write_text(HARNESS % json.dumps([p.relative_to(html).as_posix() for p in pages]))
    out = chromium_dom(
        harness,
        workdir / "chromium-profile",
        budget_ms=60000,
        extra=["--allow-file-access-from-files"],
        timeout=300,
    )
    harness.unlink()
    m = re.search(r"RESULTS\n(.*)\nEND", out.stdout, re.S)
    assert m, out.stdout[-2000:] + out.stderr[-2000:]
    return [json.loads(line) for line in m.group(1).splitlines()]


def test_every_page_renders_and_every_gallery_image_loads(site, tmp_path):
    skip = {"_static", "_modules", "_sources", "_images"}
    pages = sorted(
        p
        for p in site.rglob("*.html")
        if not skip & set(p.relative_to(site).parts)
        and p.name not in ("search.html", "genindex.html")
    )
    rows = render_all(site, pages, tmp_path)
    assert len(rows) == len(pages)
    for row in rows:
        assert row["text"] > 100, f"{row['page']} rendered almost nothing"
        if row["page"].startswith("generated/"):
            assert row["described"] >= 1, f"{row['page']} documents nothing"
        assert not row["broken"], f"{row['page']}: images that did not load: {row['broken']}"
    by_page = {row["page"]: row for row in rows}
    # one executed page per example, each with at least one figure
    for example in EXAMPLES:
        page = f"auto_examples/{example.stem}.html"
        assert page in by_page, f"the gallery lacks {example.name}"
        assert by_page[page]["images"] >= 1, f"{page} shows no figure"
    # the figures themselves are not blank
    figures = sorted((site / "_images").glob("sphx_glr_plot_*_001.png"))
    assert len(figures) >= len(EXAMPLES)
    for png in figures:
        img = mpimg.imread(png)
        assert np.unique(img.reshape(-1, img.shape[-1]), axis=0).shape[0] > 20, png
    # every public name has a page in the API reference
    import rockstudy

    for name in rockstudy.__all__:
        modules = ("closedform", "motions", "risk", "similarity", "structures", "warnings")
        if name.startswith("__") or name in modules:
            continue
        assert (site / "generated" / f"rockstudy.{name}.html").is_file(), name
