// SPDX-License-Identifier: MIT
// Moves one slider of `whitted live`'s page N times in Debian's Chromium (headless, through
// playwright-core) and writes, per move, the time from the slider's input event to the full
// image shown, with the page's own split of it (bench/live_latency.py prints the summary).
// usage: node live_latency.js URL MOVES CHROMIUM OUT.json
"use strict";
const fs = require("fs");
const {chromium} = require("playwright-core");

const [address, moves, executable, out] = process.argv.slice(2);

async function settled(page) {
    await page.waitForFunction(() => document.body.dataset.live === "ready" && whittedLive.shown !== null &&
                                     JSON.stringify(whittedLive.shown) === JSON.stringify(whittedLive.values),
                               null, {timeout: 60000, polling: "raf"});
}

(async () => {
    const root = typeof process.getuid === "function" && process.getuid() === 0;
    const browser = await chromium.launch({
        executablePath: executable, headless: true,
        args: [...(root ? ["--no-sandbox"] : []), "--disable-dev-shm-usage", "--disable-gpu"],
    });
    const page = await (await browser.newContext({viewport: {width: 1400, height: 900}})).newPage();
    await page.goto(address);
    await settled(page);
    const slider = page.locator("#m0-kd-0");
    // The input event's time stamp (when the browser made it), on the page's clock (the one its
    // timings use).
    await slider.evaluate((s) => s.addEventListener("input", (e) => { window.benchInput = e.timeStamp; }));
    await slider.focus();
    const samples = [];
    for (let i = 0; i < Number(moves); ++i) {
        // Back and forth: every move changes the value, and the scene stays near the file's.
        await page.keyboard.press(i % 2 ? "ArrowLeft" : "ArrowRight");
        await settled(page);
        const sample = await page.evaluate(() => {
            const t = whittedLive.timings[whittedLive.timings.length - 1];
            return Object.assign({}, t, {input: window.benchInput, fullShownSinceInput: t.start + t.fullShown - window.benchInput,
                                         // not shown when the server took the preview first
                                         coarseShownSinceInput: t.coarseShown ? t.start + t.coarseShown - window.benchInput : null,
                                         // none when the full image was shaded again at once
                                         previewShownSinceInput: t.previewShown ? t.start + t.previewShown - window.benchInput : null});
        });
        samples.push(sample);
    }
    fs.writeFileSync(out, JSON.stringify(samples));
    await browser.close();
})().catch((e) => {
    console.error(e);
    process.exit(1);
});
