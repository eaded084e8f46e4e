# SPDX-License-Identifier: MIT
"""What both browser drivers (report_browser.py, live_browser.py) need to start Debian's Chromium
through playwright-core: the browser, a check that the tools are there, and an environment that
keeps Chromium's profile, caches and crash dumps under the test's folder."""
import os
import shutil

from harness import fail

# Debian's; $WHITTED_CHROMIUM only for browser.missing_tools, which shows a missing one fails.
CHROMIUM = os.environ.get("WHITTED_CHROMIUM", "/usr/bin/chromium")


def require_tools(tools):
    """Fails the test, naming each one missing and how to install it, unless Chromium, node and
    playwright-core (in TOOLS/node_modules) are there: the browser tests never skip."""
    missing = []
    if not os.access(CHROMIUM, os.X_OK):
        missing.append(f"{CHROMIUM} is missing: apt-get install chromium (scripts/setup --with-test-tools does)")
    if not shutil.which("node"):
        missing.append("node is missing: apt-get install nodejs (scripts/setup --with-test-tools does)")
    if not os.path.isfile(os.path.join(tools, "node_modules", "playwright-core", "package.json")):
        missing.append(f"playwright-core is not installed in {tools}: scripts/setup --with-test-tools runs "
                       "npm ci there from tests/browser/package-lock.json")
    if missing:
        fail("the browser tests need Chromium, node and playwright-core:\n  " + "\n  ".join(missing))


def chromium_env(home, tools):
    """The environment for node and Chromium: HOME and the XDG folders in HOME (made here), never
    the user's; node finds playwright-core in TOOLS."""
    for d in ("", ".config", ".cache", ".local/share", "tmp"):
        os.makedirs(os.path.join(home, d), exist_ok=True)
    return dict(os.environ, HOME=home, XDG_CONFIG_HOME=os.path.join(home, ".config"),
                XDG_CACHE_HOME=os.path.join(home, ".cache"), XDG_DATA_HOME=os.path.join(home, ".local/share"),
                TMPDIR=os.path.join(home, "tmp"), NODE_PATH=os.path.join(tools, "node_modules"))
