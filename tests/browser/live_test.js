// SPDX-License-Identifier: MIT
// Drives Debian's Chromium (headless, through playwright-core) over the page of `whitted live`:
// waits for the first image, moves a material slider with the keyboard as a user does, waits for
// the full image of the new value, saves what the page sent and shows (live_browser.py compares
// it with `whitted render` of the edited file), then writes a bad edit to the scene file and
// saves the error the page shows, then restores the file and waits for the image to come back.
// Between these it clicks a pixel (explain), shows the diffuse layer and the N data layer, saves the edited scene (and
// declines, then confirms, overwriting it) and runs the check against POV-Ray.
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
    // Only kd moved: the server shades the full image again from the first render's hits
    // (live_browser.py compares that image with `whitted render` of the edited file).
    check(last.reshaded === true, "the kd move's full image was shaded again from the last render's hits");
    console.log(`timing: coarse image shown ${last.coarseShown.toFixed(0)} ms after the change (render ${last.coarseRender} ms), ` +
                `full image ${last.fullShown.toFixed(0)} ms (render ${last.fullRender} ms)`);
    fs.writeFileSync(path.join(work, "values.json"), JSON.stringify(values));
    fs.writeFileSync(path.join(work, "page.png"), after);
    fs.writeFileSync(path.join(work, "timings.json"), JSON.stringify(timings));
    await page.screenshot({path: path.join(shots, "live.png")});

    // 2a. explain: a click on a pixel of the highlight shows its terms (live_browser.py compares
    // them with `whitted explain --json` of the saved file).
    const [px, py] = [280, 200];
    await page.locator("#image").click({position: {x: px + 0.5, y: py + 0.5}});
    await page.waitForFunction(([x, y]) => whittedLive.explained && whittedLive.explained.x === x &&
                                           whittedLive.explained.y === y, [px, py], {timeout: 30000});
    const explained = await page.evaluate(() => whittedLive.explained);
    check(JSON.stringify(explained.values) === JSON.stringify(values), "explain used the values of the image shown");
    const explainText = await page.locator("#explain").textContent();
    const ambient = explained.result.layers.ambient.map((v) => String(+v.toPrecision(6))).join(", ");
    check(explainText.includes(`(${px}, ${py})`) && explainText.includes(ambient) && explainText.includes("light 1"),
          `the explain panel shows pixel (${px}, ${py}), its ambient ${ambient} and light 1`);
    fs.writeFileSync(path.join(work, "explain.json"), JSON.stringify(explained));

    // 2b. A render layer as the view: diffuse, then back to the beauty.
    await page.selectOption("#layer", "diffuse");
    await page.waitForFunction(() => whittedLive.shownView === "diffuse" && document.body.dataset.live === "ready",
                               null, {timeout: 60000});
    const diffuse = await shownPng(page);
    check(!diffuse.equals(after), "the diffuse layer's image differs from the beauty");
    fs.writeFileSync(path.join(work, "page-diffuse.png"), diffuse);
    // A data layer as the view: the normals, as 0.5 + 0.5·n.
    await page.selectOption("#layer", "N");
    await page.waitForFunction(() => whittedLive.shownView === "N" && document.body.dataset.live === "ready",
                               null, {timeout: 60000});
    const normals = await shownPng(page);
    check(!normals.equals(after) && !normals.equals(diffuse), "the N view's image differs from the beauty and diffuse");
    fs.writeFileSync(path.join(work, "page-N.png"), normals);
    await page.screenshot({path: path.join(shots, "live-normals.png")});
    await page.selectOption("#layer", "beauty");
    await page.waitForFunction(() => whittedLive.shownView === "beauty" && document.body.dataset.live === "ready",
                               null, {timeout: 60000});
    check((await shownPng(page)).equals(after), "back to the beauty: the same image as before");
    check(!(await page.locator("#explain").evaluate((e) => e.classList.contains("stale"))), "a change of view leaves the explanation as it is (same values)");

    // 2c. Save as a new file; a second save to it is refused unless the user confirms.
    await page.fill("#save-path", "saved.yaml");
    const savedPath = path.join(path.dirname(scenePath), "saved.yaml");
    const saved = () => page.evaluate(() => whittedLive.saved);
    await page.click("#save");
    await page.waitForFunction(() => whittedLive.saved !== null, null, {timeout: 30000});
    let result = await saved();
    check(result.written && result.path === savedPath && fs.existsSync(savedPath), `saved ${result.path}`);
    check(JSON.stringify(result.values) === JSON.stringify(values), "with the values of the image shown");
    const savedText = fs.readFileSync(savedPath, "utf8");
    const dialogs = [];
    page.once("dialog", (d) => { dialogs.push(d.message()); d.dismiss(); });
    await page.evaluate(() => { whittedLive.saved = null; });
    await page.click("#save");
    await page.waitForFunction(() => whittedLive.saved !== null, null, {timeout: 30000});
    result = await saved();
    check(dialogs.length === 1 && dialogs[0].includes("Overwrite"), `the page asked before overwriting: ${dialogs}`);
    check(!result.written && fs.readFileSync(savedPath, "utf8") === savedText &&
          (await page.locator("#save-status").textContent()).includes("exists"),
          "declined: the existing file is not written and the page says it exists");
    page.once("dialog", (d) => d.accept());
    await page.evaluate(() => { whittedLive.saved = null; });
    await page.click("#save");
    await page.waitForFunction(() => whittedLive.saved !== null, null, {timeout: 30000});
    check((await saved()).written, "confirmed: the file is written again");

    // 2d. check against POV-Ray: the verdict and the wipe (live_browser.py runs `whitted check`).
    await page.click("#check");
    await page.waitForSelector("#check-result[data-verdict=pass], #check-result[data-verdict=fail], " +
                               "#check-result[data-verdict=error]", {timeout: 120000});
    const checked = await page.evaluate(() => whittedLive.checked);
    check(checked !== null, `the check ran: ${await page.locator("#check-result").textContent()}`);
    if (checked) {
        check(JSON.stringify(checked.values) === JSON.stringify(values), "the check used the values of the image shown");
        const shownVerdict = await page.locator("#check-result").textContent();
        check(shownVerdict.includes(checked.result.verdict) &&
              shownVerdict.startsWith(checked.result.passed ? "PASS" : "FAIL"), `the page shows the verdict: ${shownVerdict}`);
        const wiped = await page.evaluate(() => ["wipe-ours", "wipe-povray"].map((id) => document.getElementById(id).naturalWidth));
        check(wiped[0] > 0 && wiped[1] > 0 && (await page.locator("#wipe").isVisible()), `the wipe shows both images ${wiped}`);
        await page.locator("#wipe-at").fill("30");
        check(/inset\(0(px)? 70% 0(px)? 0(px)?\)/.test(await page.locator("#wipe-ours").evaluate((e) => e.style.clipPath)),
              "moving the wipe clips Whitted's image");
        fs.writeFileSync(path.join(work, "check.json"), JSON.stringify(checked));
        await page.screenshot({path: path.join(shots, "live-check.png"), fullPage: true});
    }

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
    check((await page.locator("#explain").evaluate((e) => e.classList.contains("stale"))), "the explanation of the edited values is dimmed now");

    // 5. A light moved: its shadow rays change, so the server cannot shade again and renders
    // (live_browser.py compares this image with `whitted render` of the edited file too).
    const lightSlider = page.locator("#l0-position-0");
    await lightSlider.focus();
    await page.keyboard.press("ArrowRight");
    await settled(page, 60000);
    const movedTimings = await page.evaluate(() => whittedLive.timings);
    check(movedTimings[movedTimings.length - 1].reshaded === false, "the light's move was rendered, not shaded again");
    const movedValues = await page.evaluate(() => whittedLive.shown);
    check(movedValues.lights && movedValues.lights[0] && Array.isArray(movedValues.lights[0].position),
          `the light's position is among the values: ${JSON.stringify(movedValues)}`);
    fs.writeFileSync(path.join(work, "values-moved.json"), JSON.stringify(movedValues));
    fs.writeFileSync(path.join(work, "page-moved.png"), await shownPng(page));

    // The server's two refusals of the save over the existing file (409, before the page asked)
    // are logged by Chromium as failed loads: expected, and only those.
    const refused = "Failed to load resource: the server responded with a status of 409 (Conflict)";
    check(errors.filter((e) => e === refused).length === 2, "the two saves over the existing file met 409 first");
    const pageErrors = errors.filter((e) => e !== refused);
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
