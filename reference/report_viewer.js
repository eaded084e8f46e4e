// SPDX-License-Identifier: MIT
// The viewer of a `whitted check` report (docs/validation.md, "The report"), written into
// report.html. Everything it shows comes from window.WHITTED_REPORT (report-data.js, loaded by a
// <script> tag): from file:// the page may neither fetch its sibling files nor read back the
// pixels of an <img>. Images are drawn with putImageData and magnified by whole factors with
// smoothing off, so one image pixel is always a square of zoom x zoom screen pixels.
"use strict";
(function () {
    const data = window.WHITTED_REPORT;
    if (!data || data.format !== 2) return;  // the page still shows its static images
    const width = data.width, height = data.height, count = width * height;
    const $ = (id) => document.getElementById(id);
    const view = $("view"), ctx = view.getContext("2d");

    // report-data.js's encoding (reference/report.cpp, encode_words): base64 of zlib-deflated
    // byte planes of zig-zag folded differences from the gradient prediction left + up -
    // upper-left, channel by channel; the words are the bits of binary32 values ("float32") or
    // 16-bit codes, each value float(code) x code_step ("codes16").
    async function decode_image(image, n) {
        const binary = atob(image.data);
        const bytes = new Uint8Array(binary.length);
        for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
        const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("deflate"));
        const planes = new Uint8Array(await new Response(stream).arrayBuffer());
        if (n !== 3 * width * height) throw new Error("report-data.js: not an RGB image of " + width + "x" + height);
        const size = image.encoding === "float32" ? 4 : image.encoding === "codes16" ? 2 : 0;
        if (!size) throw new Error("report-data.js: unknown encoding " + image.encoding);
        if (planes.length !== size * n) throw new Error("report-data.js: " + planes.length + " bytes, expected " + size * n);
        const words = size === 4 ? new Uint32Array(n) : new Uint16Array(n);
        const mask = size === 4 ? 0xffffffff : 0xffff;
        for (let c = 0, i = 0; c < 3; ++c)
            for (let y = 0; y < height; ++y)
                for (let x = 0; x < width; ++x, ++i) {
                    let folded = 0;
                    for (let k = size - 1; k >= 0; --k) folded = folded * 256 + planes[k * n + i];
                    // Unfolded by arithmetic on whole numbers (exact below 2^53), then reduced modulo 2^32
                    // or 2^16 as encode_words computed it.
                    const r = folded % 2 ? -(folded + 1) / 2 : folded / 2;
                    const at = (px, py) => words[(py * width + px) * 3 + c];
                    const predicted = x > 0 && y > 0 ? at(x - 1, y) + at(x, y - 1) - at(x - 1, y - 1)
                                    : x > 0 ? at(x - 1, y) : y > 0 ? at(x, y - 1) : 0;
                    const w = predicted + r;
                    words[(y * width + x) * 3 + c] = size === 4 ? w >>> 0 : w & mask;
                }
        if (size === 4) return new Float32Array(words.buffer);
        const out = new Float32Array(n);
        for (let i = 0; i < n; ++i) out[i] = Math.fround(words[i] * image.code_step);
        return out;
    }

    // A value in codes with one decimal, as `whitted check` prints it (fmt's "{:.1f}" of v x 65535).
    // toFixed rounds an exact tie up, fmt to even; of a binary value x 65535 only n + .25 and
    // n + .75 are ties, and only n + .25 rounds differently.
    function codes(v) {
        const x = v * 65535;
        if (Number.isNaN(x)) return "nan";
        if (!Number.isFinite(x)) return x > 0 ? "inf" : "-inf";
        const frac = x - Math.floor(x);
        if (frac === 0.25) return (Math.floor(x) + 0.2).toFixed(1);
        return x.toFixed(1);
    }

    // The sRGB curve (IEC 61966-2-1) on values clamped to [0, 1], as ours.png and povray.png.
    function srgb8(v) {
        if (!(v > 0)) return 0;
        if (v >= 1) return 255;
        const e = v <= 0.0031308 ? 12.92 * v : 1.055 * Math.pow(v, 1 / 2.4) - 0.055;
        return Math.round(e * 255);
    }

    // The heat map's colours (reference/report.cpp, heat_colour) with `t` codes for the tolerance.
    function heat(d, t, out, o) {
        t = t > 0 ? t : 1;
        let r, g, b;
        if (!(d > t) && !Number.isNaN(d)) {
            const u = d / t;
            r = 0.25 * u, g = 0.55 * u, b = u;
        } else {
            const u = Number.isNaN(d) ? 1 : Math.min((d - t) / t, 1);
            r = 1, g = 0.85 * (1 - u), b = 0;
        }
        out[o] = Math.round(r * 255), out[o + 1] = Math.round(g * 255), out[o + 2] = Math.round(b * 255), out[o + 3] = 255;
    }

    function canvas_of(fill) {
        const c = document.createElement("canvas");
        c.width = width, c.height = height;
        const image = c.getContext("2d").createImageData(width, height);
        fill(image.data);
        c.getContext("2d").putImageData(image, 0, 0);
        return c;
    }

    const state = {
        zoom: 1, panX: 0, panY: 0, wipe: Math.floor(width / 2), left: "whitted", right: "povray",
        threshold: data.tolerance_codes, probe: null, ready: false, sources: {},
    };
    let whitted, povray, difference, layers = [];

    function image_canvas(values) {
        return canvas_of((px) => {
            for (let i = 0; i < count; ++i)
                for (let ch = 0; ch < 3; ++ch) px[4 * i + ch] = srgb8(values[3 * i + ch]), px[4 * i + 3] = 255;
        });
    }
    function difference_canvas() {
        return canvas_of((px) => { for (let i = 0; i < count; ++i) heat(difference[i], state.threshold, px, 4 * i); });
    }

    // Largest |Whitted - POV-Ray| of the three channels, in codes, as the heat map computes it
    // (float subtraction, then the largest; NaN when any channel is NaN).
    function pixel_difference(i) {
        let m = 0;
        for (let ch = 0; ch < 3; ++ch) {
            const d = Math.abs(Math.fround(whitted[3 * i + ch] - povray[3 * i + ch]));
            if (Number.isNaN(d)) return NaN;
            m = Math.max(m, d);
        }
        return m * 65535;
    }

    function fit() {
        // Room for the probe beside the view (about 420 pixels) when the window has it.
        const maxW = Math.min(960, Math.max(320, window.innerWidth - 520)), maxH = 720;
        state.zoom = Math.max(1, Math.min(64, Math.floor(Math.min(maxW / width, maxH / height))));
        view.width = Math.min(maxW, width * state.zoom);
        view.height = Math.min(maxH, height * state.zoom);
        state.panX = Math.round((width * state.zoom - view.width) / 2);
        state.panY = Math.round((height * state.zoom - view.height) / 2);
        clamp_pan();
    }
    function clamp_pan() {
        const z = state.zoom;
        state.panX = Math.round(Math.min(Math.max(state.panX, Math.min(0, (width * z - view.width) / 2)),
                                         Math.max(0, width * z - view.width)));
        state.panY = Math.round(Math.min(Math.max(state.panY, Math.min(0, (height * z - view.height) / 2)),
                                         Math.max(0, height * z - view.height)));
    }
    // Zooms to `z` keeping the image point under screen point (sx, sy) where it is.
    function zoom_to(z, sx, sy) {
        z = Math.max(1, Math.min(64, Math.round(z)));
        if (sx === undefined) sx = view.width / 2, sy = view.height / 2;
        const ix = (sx + state.panX) / state.zoom, iy = (sy + state.panY) / state.zoom;
        state.zoom = z;
        state.panX = Math.round(ix * z - sx), state.panY = Math.round(iy * z - sy);
        clamp_pan();
        draw();
    }

    function draw_source(source, x0, x1) {
        const z = state.zoom;
        // The visible whole image pixels of columns [x0, x1), drawn at whole-pixel screen positions.
        const sx0 = Math.max(x0, Math.floor(state.panX / z)), sx1 = Math.min(x1, Math.ceil((state.panX + view.width) / z));
        const sy0 = Math.max(0, Math.floor(state.panY / z)), sy1 = Math.min(height, Math.ceil((state.panY + view.height) / z));
        if (sx1 <= sx0 || sy1 <= sy0) return;
        ctx.drawImage(state.sources[source], sx0, sy0, sx1 - sx0, sy1 - sy0, sx0 * z - state.panX, sy0 * z - state.panY,
                      (sx1 - sx0) * z, (sy1 - sy0) * z);
    }

    function draw() {
        if (!state.ready) return;
        ctx.imageSmoothingEnabled = false;
        ctx.fillStyle = "#777";
        ctx.fillRect(0, 0, view.width, view.height);
        draw_source(state.left, 0, state.wipe);
        draw_source(state.right, state.wipe, width);
        const z = state.zoom;
        const wx = state.wipe * z - state.panX;
        ctx.fillStyle = "#fff";
        ctx.fillRect(wx - 1, 0, 1, view.height);
        if (state.probe) {
            const [x, y] = state.probe;
            ctx.strokeStyle = "#ff00ff";
            ctx.lineWidth = 2;
            ctx.strokeRect(x * z - state.panX - 2, y * z - state.panY - 2, z + 4, z + 4);
        }
        $("zoom-value").textContent = z + "\u00d7";
        $("wipe-value").textContent = state.wipe;
    }

    function cell(text, cls) {
        const td = document.createElement("td");
        td.textContent = text;
        if (cls) td.className = cls;
        return td;
    }
    function row(table, name, values, id, cls) {
        const tr = document.createElement("tr");
        const th = document.createElement("th");
        th.textContent = name;
        tr.appendChild(th);
        ["R", "G", "B"].forEach((channel, ch) => {
            const td = cell(values[ch], cls && cls[ch]);
            if (id) td.id = "probe-" + id + "-" + channel;
            tr.appendChild(td);
        });
        table.appendChild(tr);
    }

    function probe(x, y) {
        x = Math.max(0, Math.min(width - 1, Math.floor(x)));
        y = Math.max(0, Math.min(height - 1, Math.floor(y)));
        state.probe = [x, y];
        $("probe-x").value = x;
        $("probe-y").value = y;
        const i = y * width + x;
        const out = $("probe-values");
        out.textContent = "";
        const where = document.createElement("p");
        where.id = "probe-where";
        where.textContent = "pixel (" + x + ", " + y + "): column " + x + " from the left, row " + y + " from the top";
        out.appendChild(where);
        const table = document.createElement("table");
        const head = document.createElement("tr");
        ["codes", "R", "G", "B"].forEach((t) => { const th = document.createElement("th"); th.textContent = t; head.appendChild(th); });
        table.appendChild(head);
        const w = [0, 1, 2].map((ch) => whitted[3 * i + ch]), p = [0, 1, 2].map((ch) => povray[3 * i + ch]);
        row(table, "Whitted", w.map(codes), "whitted");
        row(table, "POV-Ray", p.map(codes), "povray");
        const d = [0, 1, 2].map((ch) => Math.abs(Math.fround(w[ch] - p[ch])));
        row(table, "|difference|", d.map(codes), "difference",
            d.map((v) => (v * 65535 > state.threshold || Number.isNaN(v) ? "beyond" : "within")));
        out.appendChild(table);
        const largest = pixel_difference(i);
        const verdict = document.createElement("p");
        verdict.id = "probe-verdict";
        verdict.textContent = "largest channel difference " + (Number.isNaN(largest) ? "nan" : largest.toFixed(1)) +
                              " codes: " + (largest > state.threshold || Number.isNaN(largest) ? "beyond" : "within") +
                              " the threshold of " + state.threshold + " (tolerance " + data.tolerance_codes + ")";
        out.appendChild(verdict);
        if (layers.length) {
            const h = document.createElement("h3");
            h.textContent = "Whitted's terms (render layers)";
            out.appendChild(h);
            const t = document.createElement("table");
            t.id = "probe-layers";
            const head2 = head.cloneNode(true);
            head2.firstChild.textContent = "layer (codes)";
            t.appendChild(head2);
            for (const layer of layers.filter((l) => !/^light\d+$/.test(l.name)))
                row(t, layer.name, [0, 1, 2].map((ch) => codes(layer.values[3 * i + ch])), "layer-" + layer.name);
            row(t, "= Whitted", w.map(codes));
            for (const layer of layers.filter((l) => /^light\d+$/.test(l.name)))
                row(t, layer.name + " (kd + ks terms)", [0, 1, 2].map((ch) => codes(layer.values[3 * i + ch])),
                    "layer-" + layer.name);
            out.appendChild(t);
            const note = document.createElement("p");
            note.className = "help";
            note.textContent = "ambient + diffuse + specular + mirror + transmission + background is Whitted's value (summed in float, " +
                               "in that order); light<k> is light k's share of diffuse + specular.";
            out.appendChild(note);
        }
        draw();
    }

    function set_threshold(t) {
        if (!(t >= 0)) return;
        state.threshold = t;
        $("threshold").value = t;
        $("threshold-value").value = t;
        let above = 0;
        for (let i = 0; i < count; ++i) if (!(difference[i] <= t)) ++above;
        $("above").textContent = above + " of " + count + " pixels above " + t + " codes";
        state.sources.diff = difference_canvas();
        if (state.probe) probe(state.probe[0], state.probe[1]);
        else draw();
    }
    function set_wipe(x) {
        state.wipe = Math.max(0, Math.min(width, Math.round(x)));
        $("wipe").value = state.wipe;
        draw();
    }
    function set_sides(left, right) {
        state.left = left, state.right = right;
        $("left").value = left, $("right").value = right;
        draw();
    }

    function image_point(event) {
        const r = view.getBoundingClientRect();
        const sx = (event.clientX - r.left) * view.width / r.width, sy = (event.clientY - r.top) * view.height / r.height;
        return [sx, sy, (sx + state.panX) / state.zoom, (sy + state.panY) / state.zoom];
    }

    function wire() {
        $("wipe").addEventListener("input", (e) => set_wipe(Number(e.target.value)));
        $("left").addEventListener("change", (e) => set_sides(e.target.value, state.right));
        $("right").addEventListener("change", (e) => set_sides(state.left, e.target.value));
        $("zoom-in").addEventListener("click", () => zoom_to(state.zoom * 2));
        $("zoom-out").addEventListener("click", () => zoom_to(state.zoom / 2));
        $("zoom-fit").addEventListener("click", () => { fit(); draw(); });
        $("threshold").addEventListener("input", (e) => set_threshold(Number(e.target.value)));
        $("threshold-value").addEventListener("change", (e) => set_threshold(Number(e.target.value)));
        const from_inputs = () => probe(Number($("probe-x").value), Number($("probe-y").value));
        $("probe-x").addEventListener("change", from_inputs);
        $("probe-y").addEventListener("change", from_inputs);
        let drag = null;
        view.addEventListener("pointerdown", (e) => {
            drag = {x: e.clientX, y: e.clientY, panX: state.panX, panY: state.panY, moved: false};
            view.setPointerCapture(e.pointerId);
        });
        view.addEventListener("pointermove", (e) => {
            if (!drag) return;
            const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
            if (Math.abs(dx) + Math.abs(dy) > 3) drag.moved = true;
            if (!drag.moved) return;
            state.panX = drag.panX - dx, state.panY = drag.panY - dy;
            clamp_pan();
            draw();
        });
        view.addEventListener("pointerup", (e) => {
            if (drag && !drag.moved) {
                const [, , ix, iy] = image_point(e);
                if (ix >= 0 && iy >= 0 && ix < width && iy < height) probe(ix, iy);
            }
            drag = null;
            view.focus();
        });
        view.addEventListener("wheel", (e) => {
            e.preventDefault();
            const [sx, sy] = image_point(e);
            zoom_to(e.deltaY < 0 ? state.zoom * 2 : state.zoom / 2, sx, sy);
        }, {passive: false});
        view.addEventListener("keydown", (e) => {
            const step = e.shiftKey ? 32 : 1;
            const moves = {ArrowLeft: [-1, 0], ArrowRight: [1, 0], ArrowUp: [0, -1], ArrowDown: [0, 1]};
            if (moves[e.key]) {
                const [dx, dy] = moves[e.key];
                if (e.shiftKey) {
                    state.panX += dx * step * 4, state.panY += dy * step * 4;
                    clamp_pan();
                    draw();
                } else {
                    const [x, y] = state.probe || [Math.floor(width / 2), Math.floor(height / 2)];
                    probe(x + dx, y + dy);
                }
            } else if (e.key === "+" || e.key === "=") zoom_to(state.zoom * 2);
            else if (e.key === "-") zoom_to(state.zoom / 2);
            else if (e.key === "0") { fit(); draw(); }
            else if (e.key === "[") set_wipe(state.wipe - Math.max(1, Math.round(width / 32)));
            else if (e.key === "]") set_wipe(state.wipe + Math.max(1, Math.round(width / 32)));
            else if (e.key === "1") set_sides("whitted", "povray");
            else if (e.key === "2") set_sides("whitted", "diff");
            else if (e.key === "3") set_sides("povray", "diff");
            else return;
            e.preventDefault();
        });
        for (const tr of document.querySelectorAll("tr[data-x]"))
            tr.addEventListener("click", () => probe(Number(tr.dataset.x), Number(tr.dataset.y)));
    }

    async function start() {
        whitted = await decode_image(data.whitted, 3 * count);
        povray = await decode_image(data.povray, 3 * count);
        for (const layer of data.layers) layers.push({name: layer.name, values: await decode_image(layer.values, 3 * count)});
        difference = new Float64Array(count);
        for (let i = 0; i < count; ++i) difference[i] = pixel_difference(i);
        state.sources.whitted = image_canvas(whitted);
        state.sources.povray = image_canvas(povray);
        $("viewer").hidden = false;
        $("viewer-missing").hidden = true;
        fit();
        wire();
        state.ready = true;
        set_threshold(data.tolerance_codes);
        const worst = data.worst_pixels[0];
        probe(worst ? worst.x : Math.floor(width / 2), worst ? worst.y : Math.floor(height / 2));
        document.body.dataset.viewer = "ready";  // for tests and scripts: the data is decoded
    }
    window.whittedViewer = state;
    start().catch((error) => {
        $("viewer-missing").textContent = "The viewer could not read report-data.js: " + error;
        document.body.dataset.viewer = "error";
    });
})();
