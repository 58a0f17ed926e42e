// End-to-end test of the dashboard in a real browser (ctest: dashboard_e2e). Starts
// `piezoshift serve --daq sim --http-port 0 --fault sgs-open@T`, opens the page in Debian's
// headless Chromium through playwright-core (no browser is downloaded), and checks:
//   the stream runs at >= 20 updates/s; a click on "Move absolute" to Z = 5 um shows in the scope's
//   position trace and the readout within 2 s; GCS POS? (a second client) sees that move; a GCS
//   MOV is seen on the page; the injected fault is shown with its reason; screenshots are kept.
//   node e2e/dashboard_e2e.mjs --cli PATH/piezoshift --artifacts DIR
import { spawn } from "node:child_process";
import { existsSync, mkdirSync } from "node:fs";
import net from "node:net";
import { join } from "node:path";

const args = process.argv.slice(2);
const opt = (n) => (args.indexOf(n) >= 0 ? args[args.indexOf(n) + 1] : undefined);
const cli = opt("--cli");
const artifacts = opt("--artifacts") || ".";
const CHROMIUM = "/usr/bin/chromium";
const FAULT_AT_S = 20;

let failures = 0;
let passes = 0;
function check(ok, what) {
  if (ok) passes++;
  else failures++;
  console.log(`${ok ? "ok  " : "FAIL"} ${what}`);
}
function fatal(msg) {
  console.error(`dashboard_e2e: ${msg}`);
  process.exit(1);
}

if (!cli || !existsSync(cli)) fatal(`--cli ${cli}: no such program`);
// A missing browser is a failure, never a skip: scripts/install-deps installs it.
if (!existsSync(CHROMIUM)) fatal(`${CHROMIUM} is missing: run scripts/install-deps (Debian's chromium)`);
let chromium;
try {
  ({ chromium } = await import("playwright-core"));
} catch (e) {
  fatal(`playwright-core is missing (${e.message}): run scripts/install-deps (npm ci in web/dashboard)`);
}
mkdirSync(artifacts, { recursive: true });

// ---- the server
const server = spawn(cli, ["serve", "--daq", "sim", "--port", "0", "--http-port", "0",
  "--max-overruns", "1000000", "--fault", `sgs-open@${FAULT_AT_S}`, "--json"],
  { stdio: ["ignore", "pipe", "pipe"] });
let out = "";
server.stdout.on("data", (d) => { out += d; });
server.stderr.on("data", (d) => process.stderr.write(d));
const started = Date.now();
while (!/GCS 2\.0 on 127\.0\.0\.1:\d+/.test(out)) {
  if (Date.now() - started > 30000 || server.exitCode !== null) fatal(`serve did not start:\n${out}`);
  await new Promise((r) => setTimeout(r, 20));
}
const httpPort = Number(/dashboard on http:\/\/127\.0\.0\.1:(\d+)\//.exec(out)[1]);
const gcsPort = Number(/GCS 2\.0 on 127\.0\.0\.1:(\d+)/.exec(out)[1]);
const url = `http://127.0.0.1:${httpPort}/`;
console.log(`serve: dashboard ${url}, GCS port ${gcsPort}`);

// A tiny GCS client (one line out, one answer in).
function gcsQuery(line) {
  return new Promise((resolve, reject) => {
    // A set command answers nothing: half-close, and the server closes once it is handled.
    const query = line.includes("?");
    const sock = net.connect(gcsPort, "127.0.0.1", () => {
      sock.write(line + "\n");
      if (!query) sock.end();
    });
    let buf = "";
    sock.setTimeout(5000, () => { sock.destroy(); reject(new Error(`GCS ${line}: timeout`)); });
    sock.on("data", (d) => {
      buf += d;
      if (query && /[^ ]\n$/.test(buf)) { sock.end(); resolve(buf); }
    });
    sock.on("end", () => resolve(buf));
    sock.on("error", reject);
  });
}
const zOf = (answer) => Number(/Z=(-?[\d.]+)/.exec(answer)?.[1]);

const browser = await chromium.launch({ executablePath: CHROMIUM, args: ["--no-sandbox"] });
try {
  const page = await browser.newPage({ viewport: { width: 1500, height: 960 } });
  page.on("pageerror", (e) => check(false, `page error: ${e.message}`));
  await page.goto(url);
  await page.waitForFunction(() => document.getElementById("pill-link").textContent === "STREAM LIVE",
    null, { timeout: 10000 });
  check(true, "page loaded, event stream live");

  // Update rate, over 2 s.
  const e0 = await page.evaluate(() => window.piezoshift.events());
  await page.waitForTimeout(2000);
  const e1 = await page.evaluate(() => window.piezoshift.events());
  const rate = (e1 - e0) / 2;
  check(rate >= 20, `stream: ${rate} updates/s (>= 20)`);

  await page.click("#btn-servo-on");
  await page.waitForFunction(() => document.getElementById("pill-servo").textContent === "SERVO ON",
    null, { timeout: 5000 });
  await page.fill("#move-z", "5");
  await page.fill("#move-u", "0");
  await page.fill("#move-v", "0");
  // Timed in the page, from the click's own event to the frame that shows 5 um, so that
  // playwright's own latency (actionability checks, polling) is not counted.
  await page.evaluate(() => {
    document.getElementById("btn-move").addEventListener("click", () => {
      window.__clicked = performance.now();
    }, { capture: true, once: true });
  });
  await page.click("#btn-move");
  // The scope's Z position trace (series 2) and the readout, both within 10 nm of 5 um.
  const handle = await page.waitForFunction(() => {
    const z = window.piezoshift.charts.z.data[2];
    const last = z.length ? z[z.length - 1] : NaN;
    const readout = Number(document.getElementById("pos-z").textContent);
    return Math.abs(last - 5) < 0.01 && Math.abs(readout - 5) < 0.01 &&
      performance.now() - window.__clicked;
  }, null, { timeout: 4000, polling: "raf" }).catch(() => null);
  const ms = handle ? await handle.jsonValue() : NaN;
  check(ms < 2000, `move to Z = 5 um seen in the scope trace and the readout ${ms.toFixed(0)} ms after the click (< 2000)`);

  const pos = zOf(await gcsQuery("POS?"));
  check(Math.abs(pos - 5) < 0.01, `GCS POS? after the dashboard's move: Z=${pos}`);
  await page.screenshot({ path: join(artifacts, "dashboard.png") });

  await gcsQuery("SVO Z 1 U 1 V 1");
  await gcsQuery("MOV Z 3");
  const seen = await page.waitForFunction(() =>
    Math.abs(Number(document.getElementById("pos-z").textContent) - 3) < 0.01,
  null, { timeout: 2000, polling: 20 }).then(() => true, () => false);
  check(seen, "a GCS client's MOV Z 3 shows on the page within 2 s");

  // An error from the server is shown: a move beyond the travel is GCS error 7.
  await page.fill("#move-z", "50");
  await page.click("#btn-move");
  const shown = await page.waitForFunction(() =>
    document.getElementById("log").textContent.includes("GCS error 7"),
  null, { timeout: 3000 }).then(() => true, () => false);
  check(shown, "a refused move shows GCS error 7 on the page");

  // The fault, with its reason.
  const faulted = await page.waitForFunction(() =>
    !document.getElementById("fault-banner").classList.contains("hidden") &&
    document.getElementById("fault-reason").textContent.includes("sgs-rail"),
  null, { timeout: (FAULT_AT_S + 20) * 1000 }).then(() => true, () => false);
  const reason = await page.textContent("#fault-banner");
  check(faulted, `fault shown: ${reason.replace(/\s+/g, " ").trim()}`);
  await page.waitForTimeout(300);
  await page.screenshot({ path: join(artifacts, "dashboard-fault.png") });
  console.log(`screenshots: ${join(artifacts, "dashboard.png")}, dashboard-fault.png`);
} catch (e) {
  check(false, `unexpected: ${e.stack || e}`);
} finally {
  await browser.close();
  server.kill("SIGTERM");
  const code = await new Promise((r) => (server.exitCode !== null ? r(server.exitCode) : server.on("exit", r)));
  check(code === 0, `serve exited with ${code} after SIGTERM`);
}
console.log(`dashboard_e2e: ${passes} passed, ${failures} failed`);
process.exit(failures === 0 ? 0 : 1);
