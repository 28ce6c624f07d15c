// Screenshot of a page in a running headless Chromium (--remote-debugging-port), taken once the
// page sets document.title to "ready" (or after the timeout): node cdp_screenshot.mjs PORT URL
// OUT.png [TIMEOUT_S]. Prints the page's final title. Needs Node >= 20 (--experimental-websocket
// on 20, built in from 22).
import fs from 'node:fs';

const [port, url, out, timeoutS = '90'] = process.argv.slice(2);
const target = await (await fetch(`http://127.0.0.1:${port}/json/new?about:blank`, { method: 'PUT' })).json();
const ws = new WebSocket(target.webSocketDebuggerUrl);
await new Promise((resolve, reject) => { ws.onopen = resolve; ws.onerror = reject; });
let nextId = 1;
const pending = new Map();
ws.onmessage = (event) => {
  const msg = JSON.parse(event.data);
  if (msg.id && pending.has(msg.id)) { pending.get(msg.id)(msg); pending.delete(msg.id); }
};
const send = (method, params = {}) => new Promise((resolve) => {
  const id = nextId++;
  pending.set(id, resolve);
  ws.send(JSON.stringify({ id, method, params }));
});
await send('Emulation.setDeviceMetricsOverride', { width: 800, height: 600, deviceScaleFactor: 1, mobile: false });
await send('Page.navigate', { url });
const deadline = Date.now() + Number(timeoutS) * 1000;
let title = '';
while (Date.now() < deadline) {
  await new Promise((r) => setTimeout(r, 500));
  const r = await send('Runtime.evaluate', { expression: 'document.title', returnByValue: true });
  title = r.result?.result?.value ?? '';
  if (title.startsWith('ready') || title.startsWith('error')) break;
}
const shot = await send('Page.captureScreenshot', { format: 'png' });
fs.writeFileSync(out, Buffer.from(shot.result.data, 'base64'));
console.log(title || 'timeout');
ws.close();
process.exit(0);
