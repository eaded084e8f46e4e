// SPDX-License-Identifier: MIT
// Drives Debian's Chromium (headless, through playwright-core) over the page of `whitted live`:
// waits for the first image, moves a material slider with the keyboard as a user does, waits for
// the full image of the new value, saves what the page sent and shows (live_browser.py compares
// it with `whitted render` of the edited file), then writes a bad edit to the scene file and
// saves the error the page shows, then restores the file and waits for the image to come back.
// usage: node live_test.js URL SCENE WORK_DIR SCREENSHOT_DIR CHROMIUM
"use strict";
const fs = require("fs");
const path = require("path");
const {chromium} = require("playwright-core");

const [address, scenePath, work, shots, executable] = process.argv.slice(2);
const problems = [];
function check(ok, message) {
    if (!ok) problems.push(message);
    console.log((ok ? "ok    " : "FAIL  ") + message);
}

async function shownPng(page) {
    return Buffer.from(await page.evaluate(async () => {
        const bytes = new Uint8Array(await whittedLive.fullBlob.arrayBuffer());
        let text = "";
        for (const b of bytes) text += String.fromCharCode(b);
        return btoa(text);
    }), "base64");
}

// The page has shown the full image of the values it holds now.
async function settled(page, timeout) {
    await page.waitForFunction(() => document.body.dataset.live === "ready" && whittedLive.shown !== null &&
                                     JSON.stringify(whittedLive.shown) === JSON.stringify(whittedLive.values),
                               null, {timeout});
}

(async () => {
    const root = typeof process.getuid === "function" && process.getuid() === 0;
    const browser = await chromium.launch({
        executablePath: executable, headless: true,
        args: [...(root ? ["--no-sandbox"] : []), "--disable-dev-shm-usage", "--disable-gpu"],
    });
    const context = await browser.newContext({viewport: {width: 1400, height: 900}});
    const blocked = [];
    let decoy = 0;
    // No network beyond the server under test: anything else is aborted and fails the test,
    // except the one decoy the test sends itself to show that the route works.
    await context.route("**/*", (route) => {
        const u = route.request().url();
        if (u.startsWith(address)) return route.continue();
        if (u === "http://whitted-test.invalid/decoy") ++decoy;
        else blocked.push(u);
        return route.abort();
    });
    const page = await context.newPage();
    const errors = [];
    page.on("pageerror", (e) => errors.push(String(e)));
    page.on("console", (m) => { if (m.type() === "error") errors.push(m.text()); });

    // 1. The first image.
    const opened = Date.now();
    await page.goto(address);
    await settled(page, 60000);
    check(true, `first full image ${Date.now() - opened} ms after opening the page`);
    const before = await shownPng(page);

    // 2. A material slider moved with the keyboard: kd's red channel, five steps right.
    const slider = page.locator("#m0-kd-0");
    const start = Number(await slider.inputValue());
    await slider.focus();
    for (let i = 0; i < 5; ++i) await page.keyboard.press("ArrowRight");
    await settled(page, 60000);
    const values = await page.evaluate(() => whittedLive.shown);
    const kd = values.materials && Object.values(values.materials)[0] && Object.values(values.materials)[0].kd;
    check(Array.isArray(kd) && Math.abs(kd[0] - (start + 0.05)) < 1e-9, `kd red moved ${start} -> ${kd && kd[0]}`);
    const after = await shownPng(page);
    check(!after.equals(before), "the image changed after the slider moved");
    const timings = await page.evaluate(() => whittedLive.timings);
    const last = timings[timings.length - 1];
    console.log(`timing: coarse image shown ${last.coarseShown.toFixed(0)} ms after the change (render ${last.coarseRender} ms), ` +
                `full image ${last.fullShown.toFixed(0)} ms (render ${last.fullRender} ms)`);
    fs.writeFileSync(path.join(work, "values.json"), JSON.stringify(values));
    fs.writeFileSync(path.join(work, "page.png"), after);
    fs.writeFileSync(path.join(work, "timings.json"), JSON.stringify(timings));
    await page.screenshot({path: path.join(shots, "live.png")});

    // 3. A bad edit of the file: the page shows the error where the image was.
    const original = fs.readFileSync(scenePath, "utf8");
    const bad = original.replace(/\bp: 10\b/, "p: [10");
    check(bad !== original, "the bad edit applies to the scene");
    fs.writeFileSync(scenePath, bad);
    await page.waitForSelector("body[data-live=error]", {timeout: 20000});
    const error = await page.locator("#error").textContent();
    check(error.startsWith(scenePath + ":"), `the page shows the error: ${error}`);
    check(!(await page.locator("#image").isVisible()), "the image is hidden while the file does not load");
    fs.writeFileSync(path.join(work, "page-error.txt"), error);
    await page.screenshot({path: path.join(shots, "live-error.png")});

    // 4. The file mended: the image comes back, from the file's values (the panels start again).
    fs.writeFileSync(scenePath, original);
    await settled(page, 60000);
    check(await page.locator("#image").isVisible(), "the image is back once the file loads again");
    check((await shownPng(page)).equals(before), "and it is the file's own image again");

    const pageErrors = errors.slice();
    // From a blank page: the live page's own Content-Security-Policy (connect-src 'self') stops
    // its fetch before the route would see it.
    const blank = await context.newPage();
    await blank.evaluate(() => fetch("http://whitted-test.invalid/decoy").catch(() => null));
    check(decoy === 1, `the network route saw the test's own decoy request (${decoy})`);
    check(blocked.length === 0, `no requests beyond the server: ${JSON.stringify(blocked)}`);
    check(pageErrors.length === 0, `no page errors: ${JSON.stringify(pageErrors)}`);
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
