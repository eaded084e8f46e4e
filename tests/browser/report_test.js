// SPDX-License-Identifier: MIT
// Drives Debian's Chromium (headless, through playwright-core, which downloads no browser) over
// a `whitted check` report or a scripts/validate index opened from file://, and compares what
// the page shows with expect.json, which report_browser.py wrote from check's own files.
// usage: node report_test.js CASE PAGE EXPECT_JSON SCREENSHOT_DIR CHROMIUM
"use strict";
const fs = require("fs");
const path = require("path");
const url = require("url");
const {chromium} = require("playwright-core");

const [caseName, pagePath, expectPath, shots, executable] = process.argv.slice(2);
const expect = JSON.parse(fs.readFileSync(expectPath, "utf8"));
const problems = [];
function check(ok, message) {
    if (!ok) problems.push(message);
    console.log((ok ? "ok    " : "FAIL  ") + message);
}
function same(actual, expected, what) {
    const a = JSON.stringify(actual), e = JSON.stringify(expected);
    check(a === e, `${what}: page ${a}` + (a === e ? "" : `, expected ${e}`));
}

async function probeByClick(page, x, y) {
    // A real click at the centre of image pixel (x, y) on the canvas, at the viewer's zoom and pan
    // (the canvas scrolled to the top of the window first: the static view is above it, and an
    // element screenshot may have scrolled it out of view).
    await page.evaluate(() => document.getElementById("view").scrollIntoView({block: "start"}));
    const v = await page.evaluate(() => ({zoom: whittedViewer.zoom, panX: whittedViewer.panX, panY: whittedViewer.panY}));
    const box = await page.locator("#view").boundingBox();
    const sx = x * v.zoom - v.panX + v.zoom / 2, sy = y * v.zoom - v.panY + v.zoom / 2;
    if (sx < 0 || sy < 0 || sx >= box.width || sy >= box.height) {
        check(false, `pixel (${x}, ${y}) is outside the view at zoom ${v.zoom}`);
        return;
    }
    await page.mouse.click(box.x + sx, box.y + sy);
}

async function probeValues(page, withLayers) {
    return page.evaluate((names) => {
        const get = (id) => ["R", "G", "B"].map((c) => {
            const e = document.getElementById(`probe-${id}-${c}`);
            return e ? e.textContent : null;
        });
        const out = {where: document.getElementById("probe-where").textContent, whitted: get("whitted"),
                     povray: get("povray"), layers: {}, layerTable: !!document.getElementById("probe-layers")};
        for (const n of names) out.layers[n] = get("layer-" + n);
        return out;
    }, withLayers ? expect.colour_layers : []);
}

// The colour of screen pixel (sx, sy) of the viewer's canvas (drawn from putImageData: readable).
async function viewColour(page, sx, sy) {
    return page.evaluate(([sx, sy]) => {
        const d = document.getElementById("view").getContext("2d").getImageData(sx, sy, 1, 1).data;
        return [d[0], d[1], d[2]];
    }, [sx, sy]);
}
function near(a, b, slack) {
    return a.every((v, i) => Math.abs(v - b[i]) <= slack);
}

async function reportCase(page) {
    const withLayers = caseName === "layers";
    // 1. The probe starts on the worst pixel: values as in metrics.json and the files.
    const first = expect.probes[0];
    let shown = await probeValues(page, withLayers);
    check(shown.where.startsWith(`pixel (${first.x}, ${first.y})`), `initial probe on the worst pixel: "${shown.where}"`);
    same(shown.whitted, first.whitted, `worst pixel (${first.x}, ${first.y}) Whitted codes`);
    same(shown.povray, first.povray, `worst pixel (${first.x}, ${first.y}) POV-Ray codes`);
    check(shown.layerTable === withLayers, `per-term breakdown ${withLayers ? "shown" : "absent"}`);

    // 2. Probe others by clicking on the canvas.
    for (const [k, p] of expect.probes.slice(1).entries()) {
        await probeByClick(page, p.x, p.y);
        // The probe with the breakdown on a lit pixel, for docs/layers.md.
        if (k === 0 && withLayers) await page.locator("#probe").screenshot({path: path.join(shots, "probe.png")});
        shown = await probeValues(page, withLayers);
        check(shown.where.startsWith(`pixel (${p.x}, ${p.y})`), `click probes (${p.x}, ${p.y}): "${shown.where}"`);
        same(shown.whitted, p.whitted, `(${p.x}, ${p.y}) Whitted codes (ours.exr)`);
        same(shown.povray, p.povray, `(${p.x}, ${p.y}) POV-Ray codes (povray-16bit.png)`);
        if (withLayers)
            for (const n of expect.colour_layers) same(shown.layers[n], p.layers[n], `(${p.x}, ${p.y}) layer ${n} codes`);
    }

    // 3. Keyboard: the arrow key moves the probe one pixel.
    const last = expect.probes[expect.probes.length - 1];
    await page.locator("#view").focus();
    await page.keyboard.press("ArrowRight");
    shown = await probeValues(page, false);
    check(shown.where.startsWith(`pixel (${last.x + 1}, ${last.y})`), `ArrowRight moves the probe: "${shown.where}"`);

    // 4. The wipe: Whitted on the left, the difference on the right; move it across a pixel.
    const w = expect.wipe;
    await page.selectOption("#right", "diff");
    const v = await page.evaluate(() => ({zoom: whittedViewer.zoom, panX: whittedViewer.panX, panY: whittedViewer.panY}));
    const sx = w.x * v.zoom - v.panX + Math.floor(v.zoom / 2), sy = w.y * v.zoom - v.panY + Math.floor(v.zoom / 2);
    await page.locator("#wipe").fill(String(w.x + 1));
    const leftSide = await viewColour(page, sx, sy);
    // The sRGB curve drawn by the page and the PNG's may round one 8-bit step apart.
    check(near(leftSide, w.whitted_rgb, 1), `wipe right of (${w.x}, ${w.y}): Whitted ${leftSide} vs ours.png ${w.whitted_rgb}`);
    await page.locator("#wipe").fill(String(w.x));
    const rightSide = await viewColour(page, sx, sy);
    check(near(rightSide, w.diff_rgb, 0), `wipe at (${w.x}, ${w.y}): difference ${rightSide} vs diff.png ${w.diff_rgb}`);
    await page.selectOption("#right", "povray");
    const povraySide = await viewColour(page, sx, sy);
    check(near(povraySide, w.povray_rgb, 1), `right side POV-Ray ${povraySide} vs povray.png ${w.povray_rgb}`);
    await page.locator("#wipe").fill(String(Math.floor(expect.width / 2)));
    await page.locator("#viewer").screenshot({path: path.join(shots, "report.png")});

    // 5. Zoom: whole factors, every image pixel a uniform zoom x zoom square.
    const before = v.zoom;
    await page.locator("#view").focus();
    await page.keyboard.press("+");
    const after = await page.evaluate(() => whittedViewer.zoom);
    check(after === Math.min(64, before * 2), `"+" zooms ${before} -> ${after}`);
    const uniform = await page.evaluate(() => {
        const s = whittedViewer, z = s.zoom, view = document.getElementById("view");
        const ctx = view.getContext("2d");
        // The pixel under the view's centre: all its screen pixels alike.
        const x = Math.floor((view.width / 2 + s.panX) / z), y = Math.floor((view.height / 2 + s.panY) / z);
        const block = ctx.getImageData(x * z - s.panX, y * z - s.panY, z, z).data;
        for (let i = 4; i < block.length; i += 4)
            for (let c = 0; c < 3; ++c) if (block[i + c] !== block[c]) return false;
        return z >= 2;
    });
    check(uniform, `at zoom ${after} one image pixel is a uniform ${after}x${after} block`);
    await page.keyboard.press("0");

    // 6. The threshold: pixels above it counted as the files count them.
    for (const [t, n] of Object.entries(expect.above)) {
        await page.locator("#threshold-value").fill(t);
        await page.locator("#threshold-value").dispatchEvent("change");
        const text = await page.locator("#above").textContent();
        check(text.startsWith(`${n} of ${expect.width * expect.height} pixels above`),
              `threshold ${t} codes: "${text}", the files have ${n} above`);
    }
    await page.selectOption("#left", "diff");
    await page.locator("#threshold-value").fill("0.5");
    await page.locator("#threshold-value").dispatchEvent("change");
    await page.locator("#viewer").screenshot({path: path.join(shots, "threshold.png")});

    // 7. A row of the worst-pixel table probes its pixel.
    const rows = await page.locator("tr[data-x]").count();
    check(rows === expect.worst_count, `${rows} clickable worst-pixel rows`);
    await page.locator("tr[data-x]").first().click();
    shown = await probeValues(page, false);
    check(shown.where.startsWith(`pixel (${first.x}, ${first.y})`), `worst row click probes it: "${shown.where}"`);
}

// JavaScript off: what a screenshot tool or a reader without scripts sees.
async function staticCase(page, viewport) {
    const ran = await page.evaluate(() => document.body.dataset.viewer || null);
    same(ran, null, "no script ran (body data-viewer)");
    check(await page.locator("#viewer").isHidden(), "the interactive viewer stays hidden");
    same(await page.locator("#verdict").textContent(), expect.verdict, "verdict");
    for (const [key, value] of Object.entries(expect.metrics))
        same(await page.locator(`[data-metric=${key}]`).textContent(), value, `${key} (metrics.json)`);
    const inView = async (locator, what) => {
        const box = await locator.boundingBox();
        check(box && box.y >= 0 && box.y + box.height <= viewport.height && box.x + box.width <= viewport.width,
              `${what} within the first ${viewport.width}x${viewport.height} view: ${JSON.stringify(box)}`);
    };
    await inView(page.locator("#verdict"), "verdict");
    await inView(page.locator("[data-metric=worst_error_codes]").locator("xpath=ancestor::table"), "figures table");
    for (const [src, size] of Object.entries(expect.images)) {
        const img = page.locator(`.row img[src="${src}"]`);
        same(await img.evaluate((i) => [i.complete, i.naturalWidth, i.naturalHeight]), [true, ...size], `${src} loaded`);
        await inView(img, src);
    }
    await page.screenshot({path: path.join(shots, "static.png")});
}

async function indexCase(page) {
    const thumbs = await page.evaluate(() => Array.from(document.querySelectorAll("img.thumb")).map((i) => ({
        src: i.getAttribute("src"), w: i.naturalWidth, h: i.naturalHeight, link: i.closest("a").getAttribute("href")})));
    same(thumbs.map((t) => t.src), expect.thumbnails, "thumbnails");
    for (const t of thumbs) {
        same([t.w, t.h], expect.thumb_size, `${t.src} loaded`);
        check(t.link.endsWith("/report.html"), `${t.src} links to ${t.link}`);
    }
    await page.screenshot({path: path.join(shots, "index.png")});
    // Follow the link: the report opens and its viewer starts.
    await Promise.all([page.waitForNavigation(), page.locator("img.thumb").first().click()]);
    await page.waitForSelector("body[data-viewer=ready]", {timeout: 20000});
    check(true, "the report opened from the index, viewer ready");
}

(async () => {
    const root = typeof process.getuid === "function" && process.getuid() === 0;
    const browser = await chromium.launch({
        executablePath: executable, headless: true,
        // As root (CI's chroot) Chromium refuses its sandbox; /dev/shm is small in a chroot.
        args: [...(root ? ["--no-sandbox"] : []), "--disable-dev-shm-usage", "--disable-gpu"],
    });
    const viewport = {width: 1400, height: 1000};
    const context = await browser.newContext({viewport, javaScriptEnabled: caseName !== "static"});
    const blocked = [];
    let decoy = 0;
    // No network: every request that is not a file:// URL is aborted and fails the test, except
    // the one decoy the test sends itself to show that the route works.
    await context.route("**/*", (route) => {
        const u = route.request().url();
        if (u.startsWith("file://")) return route.continue();
        if (u === "http://whitted-test.invalid/decoy") ++decoy;
        else blocked.push(u);
        return route.abort();
    });
    const page = await context.newPage();
    const errors = [];
    page.on("pageerror", (e) => errors.push(String(e)));
    page.on("console", (m) => { if (m.type() === "error") errors.push(m.text()); });
    const started = Date.now();
    await page.goto(url.pathToFileURL(pagePath).href);
    if (caseName === "static") {
        await staticCase(page, viewport);
    } else if (caseName !== "index") {
        await page.waitForSelector("body[data-viewer]", {timeout: 20000});
        const state = await page.evaluate(() => document.body.dataset.viewer);
        check(state === "ready", `viewer ${state} (${Date.now() - started} ms after opening)`);
        if (state === "ready") await reportCase(page);
    } else {
        await indexCase(page);
    }
    const pageErrors = errors.slice();  // before the decoy, whose failure Chromium logs as an error
    await page.evaluate(() => fetch("http://whitted-test.invalid/decoy").catch(() => null));
    check(decoy === 1, `the network route saw the test's own decoy request (${decoy})`);
    same(blocked, [], "requests other than file://");
    same(pageErrors, [], "page errors");
    await browser.close();
    if (problems.length) {
        console.log(`${problems.length} problem(s)`);
        process.exit(1);
    }
    console.log("all checks passed");
})().catch((e) => {
    console.log("FAIL  " + (e && e.stack ? e.stack : e));
    process.exit(1);
});
