#!/usr/bin/env python3
"""Checks every internal link of a built static site (the manual, mkdocs
build): each page, image, stylesheet or script a page names must be in the
site, and each #anchor must be an id on the page it points into. MkDocs 1.4
checks neither anchors nor the links its theme writes.

usage: check-site-links.py SITE_DIR
Prints one line per broken link (the page, the link, what is missing) and
exits 1 if there is any; links to other hosts are not followed.
"""
import argparse
import os
import sys
from html.parser import HTMLParser
from urllib.parse import unquote, urlsplit

# The attributes that name another file of the site, by tag.
LINKING = {"a": "href", "link": "href", "img": "src", "script": "src", "source": "src", "iframe": "src"}


class Page(HTMLParser):
    """One HTML file's anchors (its ids, and the names of its <a>) and the links it makes."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.anchors, self.links = set(), []

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if attrs.get("id"):
            self.anchors.add(attrs["id"])
        if tag == "a" and attrs.get("name"):
            self.anchors.add(attrs["name"])
        link = attrs.get(LINKING.get(tag, ""))
        if link is not None:
            self.links.append(link)


def read_site(site):
    """Every HTML page of the site, by its path relative to the site's root (with '/')."""
    pages = {}
    for folder, _, files in os.walk(site):
        for name in files:
            if name.endswith(".html"):
                path = os.path.join(folder, name)
                page = Page()
                with open(path, encoding="utf-8") as f:
                    page.feed(f.read())
                pages[os.path.relpath(path, site).replace(os.sep, "/")] = page
    return pages


def target(site, page, link):
    """The file of the site a link of `page` names (relative to the root) and its
    anchor, or None for a link that leaves the site; raises ValueError for a
    path that climbs out of the site's root."""
    parts = urlsplit(link)
    if parts.scheme or parts.netloc:
        return None
    path = unquote(parts.path)
    if not path:
        resolved = page
    else:
        base = "" if path.startswith("/") else os.path.dirname(page)
        resolved = os.path.normpath(os.path.join(base, path.lstrip("/"))).replace(os.sep, "/")
        if resolved == ".." or resolved.startswith("../"):
            raise ValueError("leaves the site's root")
        if resolved == ".":
            resolved = ""
        # A folder's page is its index.html (MkDocs' directory URLs).
        if path.endswith("/") or os.path.isdir(os.path.join(site, resolved)):
            resolved = f"{resolved}/index.html".lstrip("/")
    return resolved, unquote(parts.fragment)


def broken_links(site, pages):
    """(page, link, what is wrong) of every internal link of the site's pages
    (read_site) that points nowhere, in order."""
    broken = []
    for name in sorted(pages):
        for link in pages[name].links:
            try:
                found = target(site, name, link)
            except ValueError as e:
                broken.append((name, link, str(e)))
                continue
            if found is None:
                continue
            path, anchor = found
            if not os.path.isfile(os.path.join(site, path)):
                broken.append((name, link, f"no file {path}"))
            elif anchor and path in pages and anchor not in pages[path].anchors:
                broken.append((name, link, f"no anchor #{anchor} in {path}"))
    return broken


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("site", help="the built site's folder")
    args = ap.parse_args()
    if not os.path.isfile(os.path.join(args.site, "index.html")):
        sys.exit(f"{args.site}: no built site there (no index.html)")
    pages = read_site(args.site)
    broken = broken_links(args.site, pages)
    for page, link, why in broken:
        print(f"{page}: broken link '{link}': {why}")
    print(f"check-site-links: {len(pages)} pages, {len(broken)} broken links")
    sys.exit(1 if broken else 0)


if __name__ == "__main__":
    main()
