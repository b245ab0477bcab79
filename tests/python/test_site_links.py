"""The manual's link checker (scripts/check-site-links.py) on a tiny MkDocs
site: mkdocs build --strict passes a link to an anchor that is not there,
the checker fails on it, naming the page and the link, and passes the site
once the anchor is right."""
import os
import subprocess
import sys

CHECKER = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                       "scripts", "check-site-links.py")


def site(tmp_path, links):
    """A two-page site whose first page links to each of `links` on the second, built into tmp_path/site."""
    docs = tmp_path / "docs"
    (docs / "part").mkdir(parents=True)
    (tmp_path / "mkdocs.yml").write_text("site_name: fixture\ntheme:\n  name: material\n"
                                         "markdown_extensions:\n  - toc:\n      permalink: true\n")
    (docs / "index.md").write_text("# Home\n\n" + "".join(f"See [this]({link}).\n\n" for link in links))
    (docs / "part" / "keys.md").write_text("# Keys\n\n## Courant number\n\n"
                                           '<h3 id="mpm-courant"><code>mpm.courant</code></h3>\n\nA number.\n')
    built = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-q", "-f",
                            str(tmp_path / "mkdocs.yml"), "-d", str(tmp_path / "site")],
                           capture_output=True, text=True, timeout=120)
    assert built.returncode == 0, built.stderr
    return tmp_path / "site"


def check(path):
    return subprocess.run([sys.executable, CHECKER, str(path)], capture_output=True, text=True, timeout=60)


def test_a_broken_anchor_fails_naming_page_and_link(tmp_path):
    """Anchors of a Markdown heading and of raw HTML resolve; a misspelt one,
    which mkdocs --strict let through, does not."""
    done = check(site(tmp_path, ["part/keys.md#courant-number", "part/keys.md#mpm-courant",
                                 "part/keys.md#mpm-courrant"]))
    print(done.stdout)
    assert done.returncode == 1
    assert ("index.html: broken link 'part/keys/#mpm-courrant': no anchor #mpm-courrant in part/keys/index.html"
            in done.stdout)
    assert "1 broken links" in done.stdout


def test_a_missing_file_and_a_link_out_of_the_site_fail(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "index.html").write_text('<a href="a/">a</a> <img src="missing.png"> <a href="https://x.org/">x</a>')
    (tmp_path / "a" / "index.html").write_text('<p id="top"><a href="../../up.html">up</a> <a href="#top">top</a></p>')
    done = check(tmp_path)
    print(done.stdout)
    assert done.returncode == 1
    assert "index.html: broken link 'missing.png': no file missing.png" in done.stdout
    assert "a/index.html: broken link '../../up.html': leaves the site's root" in done.stdout
    assert "2 broken links" in done.stdout
