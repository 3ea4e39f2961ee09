// A screenshot of the project's page (tools/view/web) drawing a live view:
// the page served over HTTP on 127.0.0.1, headless Chromium driven over the
// DevTools protocol, the PNG taken once the page has drawn a few scenes.
//
//   node screenshot.js --ws ws://127.0.0.1:PORT --out view.png
//        [--width 800] [--height 600] [--cx 0] [--cz 0.25] [--ppm 1000] [--min-scenes 3]
//   node screenshot.js --serve     (only serve the page, for a desktop browser)
//
// Prints the time of the scene in the picture as {"sec":..,"nsec":..}.
// CHROMIUM overrides the browser (default /usr/bin/chromium).
'use strict';
const { spawn } = require('child_process');
const fs = require('fs');
const http = require('http');
const os = require('os');
const path = require('path');
const WebSocket = require('ws');

const WEB_ROOT = path.join(__dirname, '..', 'web');
const THREE_ROOT = path.join(__dirname, 'node_modules', 'three');
const TYPES = { '.html': 'text/html', '.js': 'text/javascript', '.css': 'text/css', '.png': 'image/png' };
// WebGL without a GPU is SwiftShader, the software renderer Chromium ships;
// Chromium is retiring its silent fallback to it, so it is asked for.
const CHROMIUM_FLAGS = ['--headless=new', '--no-sandbox', '--disable-gpu', '--use-angle=swiftshader',
  '--enable-unsafe-swiftshader', '--disable-quic', '--no-first-run', '--disable-background-networking',
  '--disable-component-update', '--disable-sync', '--disable-dev-shm-usage', '--hide-scrollbars',
  '--remote-debugging-port=0'];

// The page at /, three.js at /three/; nothing outside those two directories.
function servePage() {
  const server = http.createServer((req, res) => {
    let url;
    try { url = decodeURIComponent(new URL(req.url, 'http://localhost').pathname); } catch { return res.writeHead(400).end(); }
    const [root, rest] = url.startsWith('/three/') ? [THREE_ROOT, url.slice(7)] : [WEB_ROOT, url === '/' ? 'index.html' : url];
    const file = path.join(root, path.normalize('/' + rest));
    fs.readFile(file, (err, body) => {
      if (err) return res.writeHead(404).end();
      res.writeHead(200, { 'Content-Type': TYPES[path.extname(file)] || 'application/octet-stream' }).end(body);
    });
  });
  return new Promise((resolve, reject) => {
    server.once('error', reject);
    server.listen(0, '127.0.0.1', () => resolve(server));
  });
}

const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

function getJson(url) {
  return new Promise((resolve, reject) => {
    http.get(url, (res) => {
      let body = '';
      res.on('data', (chunk) => (body += chunk));
      res.on('end', () => { try { resolve(JSON.parse(body)); } catch (e) { reject(e); } });
    }).on('error', reject);
  });
}

// One DevTools connection: commands by id, and the first page error
// (exception, console.error, failed load) kept in `error`.
class Devtools {
  constructor(url, deadline) {
    this.deadline = deadline;
    this.ws = new WebSocket(url, { perMessageDeflate: false });
    this.next = 1;
    this.pending = new Map();
    this.error = null;
    this.ws.on('message', (data) => {
      const m = JSON.parse(data);
      const call = this.pending.get(m.id);
      if (call) {
        this.pending.delete(m.id);
        m.error ? call.reject(new Error(`${call.method}: ${m.error.message}`)) : call.resolve(m.result);
      } else if (m.method === 'Runtime.exceptionThrown') {
        const d = m.params.exceptionDetails;
        this.error = this.error || `page exception: ${(d.exception && d.exception.description) || d.text}`.split('\n')[0];
      } else if (m.method === 'Runtime.consoleAPICalled' && m.params.type === 'error') {
        this.error = this.error || `page console error: ${m.params.args.map((a) => a.value ?? a.description).join(' ')}`;
      } else if (m.method === 'Log.entryAdded' && m.params.entry.level === 'error') {
        this.error = this.error || `page error: ${m.params.entry.text} ${m.params.entry.url || ''}`.trim();
      }
    });
    this.opened = new Promise((resolve, reject) => {
      this.ws.once('open', resolve);
      this.ws.on('error', reject);
    });
    this.ws.on('close', () => {
      for (const call of this.pending.values()) call.reject(new Error(`${call.method}: the DevTools connection closed`));
      this.pending.clear();
    });
  }
  // Rejected at the deadline: a hung browser is an error, not a hang.
  send(method, params = {}) {
    return new Promise((resolve, reject) => {
      const id = this.next++;
      const timer = setTimeout(() => {
        this.pending.delete(id);
        reject(new Error(`${method}: no answer from Chromium before the deadline`));
      }, Math.max(0, this.deadline - Date.now()));
      const settle = (f) => (value) => { clearTimeout(timer); f(value); };
      this.pending.set(id, { method, resolve: settle(resolve), reject: settle(reject) });
      this.ws.send(JSON.stringify({ id, method, params }));
    });
  }
  async evaluate(expression) {
    const { result, exceptionDetails } = await this.send('Runtime.evaluate',
      { expression, returnByValue: true, awaitPromise: true });
    if (exceptionDetails) throw new Error(`page: ${exceptionDetails.text}`);
    return result.value;
  }
}

// Chromium with a fresh profile, and the page's server; `capture` may be
// called once the view's server is up, `close` always.
async function openBrowser({ width = 800, height = 600, timeoutMs = 60000 } = {}) {
  const deadline = Date.now() + timeoutMs;
  const chromium = process.env.CHROMIUM || '/usr/bin/chromium';
  try { fs.accessSync(chromium, fs.constants.X_OK); } catch { throw new Error(`no Chromium at ${chromium} (set CHROMIUM)`); }
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'cdcr-chromium-'));
  const server = await servePage();
  const child = spawn(chromium, [...CHROMIUM_FLAGS, `--user-data-dir=${profile}`, `--window-size=${width},${height}`,
    'about:blank'], { stdio: ['ignore', 'ignore', 'pipe'] });
  let stderr = '', exited = null;
  child.stderr.on('data', (d) => (stderr = (stderr + d).slice(-4000)));
  const gone = new Promise((resolve) => child.on('exit', (code, signal) => resolve((exited = signal || code))));
  child.on('error', () => {});
  let devtools = null;

  // Browser.close ends Chromium with its helper processes (a signal to the
  // browser's process leaves them to notice on their own).
  const close = async () => {
    server.close();
    if (exited === null) {
      const stubborn = setTimeout(() => child.kill('SIGKILL'), 5000);
      if (devtools) devtools.send('Browser.close').catch(() => {});
      else child.kill('SIGTERM');
      await gone;
      clearTimeout(stubborn);
    }
    if (devtools) devtools.ws.terminate();
    fs.rmSync(profile, { recursive: true, force: true, maxRetries: 5 });
  };
  const lastLine = () => stderr.trim().split('\n').pop() || 'no output';
  const check = (what) => {
    if (exited !== null) throw new Error(`chromium exited (${exited}) ${what}: ${lastLine()}`);
    if (Date.now() > deadline) throw new Error(`timed out after ${timeoutMs / 1000} s ${what}`);
  };

  try {
    // Chromium writes its DevTools port to the profile once it listens.
    const portFile = path.join(profile, 'DevToolsActivePort');
    while (!fs.existsSync(portFile) || !fs.readFileSync(portFile, 'utf8').includes('\n')) {
      check('before its DevTools port was open');
      await sleep(50);
    }
    const port = Number(fs.readFileSync(portFile, 'utf8').split('\n')[0]);
    let target;
    while (!(target = (await getJson(`http://127.0.0.1:${port}/json/list`)).find((t) => t.type === 'page'))) {
      check('before it had a page');
      await sleep(50);
    }
    devtools = new Devtools(target.webSocketDebuggerUrl, deadline);
    await devtools.opened;
    for (const domain of ['Page', 'Runtime', 'Log']) await devtools.send(`${domain}.enable`);
    await devtools.send('Emulation.setDeviceMetricsOverride', { width, height, deviceScaleFactor: 1, mobile: false });
  } catch (e) {
    await close();
    throw e;
  }

  // The page drawing `ws` with the camera given; resolves to the time of
  // the scene in the PNG written to `out`.
  const capture = async ({ ws, out, cx = 0, cz = 0.25, ppm = 1000, minScenes = 3 }) => {
    const query = new URLSearchParams({ ws, cx, cz, ppm });
    const { errorText } = await devtools.send('Page.navigate', { url: `http://127.0.0.1:${server.address().port}/?${query}` });
    if (errorText) throw new Error(`the page did not load: ${errorText}`);
    for (let scenes = 0; scenes < minScenes; await sleep(100)) {
      if (devtools.error) throw new Error(devtools.error);
      check(`before the page drew ${minScenes} scenes (it drew ${scenes})`);
      scenes = await devtools.evaluate('window.cdcrView ? window.cdcrView.scenes : 0');
    }
    // Frozen, and two frames later whatever was pending is on screen.
    const sceneTime = await devtools.evaluate(`window.cdcrView.frozen = true,
      new Promise((done) => requestAnimationFrame(() => requestAnimationFrame(() => done(window.cdcrView.sceneTime))))`);
    const { data } = await devtools.send('Page.captureScreenshot', { format: 'png' });
    if (devtools.error) throw new Error(devtools.error);
    const temporary = `${out}.${process.pid}.tmp`;
    fs.writeFileSync(temporary, Buffer.from(data, 'base64'));
    fs.renameSync(temporary, out);
    return sceneTime;
  };
  return { capture, close };
}

async function screenshot(options) {
  const browser = await openBrowser(options);
  try {
    return await browser.capture(options);
  } finally {
    await browser.close();
  }
}

module.exports = { screenshot, openBrowser, servePage };

if (require.main === module) {
  const args = process.argv.slice(2);
  const option = (name, fallback) => {
    const i = args.indexOf(`--${name}`);
    return i >= 0 ? args[i + 1] : fallback;
  };
  const fail = (message) => {
    console.error(`screenshot: ${message}`);
    process.exit(1);
  };
  if (args.includes('--serve')) {
    servePage().then((server) => console.log(`page: http://127.0.0.1:${server.address().port}/?ws=ws://127.0.0.1:PORT`), (e) => fail(e.message));
  } else {
    if (!option('ws') || !option('out')) fail('usage: screenshot.js --ws URL --out PNG [--width W --height H --cx M --cz M --ppm N --min-scenes N]');
    const n = (name, fallback) => Number(option(name, fallback));
    screenshot({ ws: option('ws'), out: option('out'), width: n('width', 800), height: n('height', 600),
      cx: n('cx', 0), cz: n('cz', 0.25), ppm: n('ppm', 1000), minScenes: n('min-scenes', 3) })
      .then((time) => console.log(JSON.stringify(time)), (e) => fail(e.message));
  }
}
