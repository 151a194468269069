// The bench's access token and its live channel. The token comes once in the printed URL
// (?token=); it is then kept in this page's memory and its tab's sessionStorage (per origin, so
// per port: another bench or another local server never sees it; it survives a reload), taken
// out of the address bar, and sent on every request as the X-Vibid-Token header. It is never a
// cookie: cookies go to every port of the host.
'use strict';

const access = (() => {
  const kKey = 'vibid-bench-token';
  const given = new URLSearchParams(location.search).get('token');
  if (given) {
    sessionStorage.setItem(kKey, given);
    history.replaceState(null, '', location.pathname);
  }
  const token = given || sessionStorage.getItem(kKey) || '';

  // Request headers with the token (and `extra`).
  function headers(extra) { return Object.assign({'X-Vibid-Token': token}, extra || {}); }

  const sleep = ms => new Promise(r => setTimeout(r, ms));

  // The live channel: Server-Sent Events read over fetch (an EventSource can send no header and
  // cannot read why it was refused). Events are dispatched by their name with their data, as an
  // EventSource does; `open` when the stream starts, `error` when it breaks (it reconnects), and
  // `refused` with the server's message when the server declines it (503: all live channels are
  // taken), after which it tries again every few seconds.
  class LiveChannel extends EventTarget {
    constructor() { super(); this.run(); }

    async run() {
      for (;;) {
        let r;
        try {
          r = await fetch('/api/live', {headers: headers(), cache: 'no-store'});
        } catch (e) {
          this.dispatchEvent(new Event('error'));
          await sleep(1000);
          continue;
        }
        if (!r.ok) {
          const j = await r.json().catch(() => ({}));
          this.dispatchEvent(new CustomEvent('refused', {detail: j.error || ('HTTP ' + r.status)}));
          await sleep(3000);
          continue;
        }
        this.dispatchEvent(new Event('open'));
        try {
          await this.read(r.body.pipeThrough(new TextDecoderStream()).getReader());
        } catch (e) { /* the stream broke: reconnect */ }
        this.dispatchEvent(new Event('error'));
        await sleep(500);
      }
    }

    async read(reader) {
      let buffer = '';
      for (;;) {
        const {value, done} = await reader.read();
        if (done) return;
        buffer += value;
        let end;
        while ((end = buffer.indexOf('\n\n')) >= 0) {
          const frame = buffer.slice(0, end);
          buffer = buffer.slice(end + 2);
          let type = 'message';
          const data = [];
          for (const line of frame.split('\n')) {
            if (line.startsWith('event: ')) type = line.slice(7);
            else if (line.startsWith('data: ')) data.push(line.slice(6));
          }
          if (data.length) this.dispatchEvent(new MessageEvent(type, {data: data.join('\n')}));
        }
      }
    }
  }

  return {headers, hasToken: token !== '', LiveChannel};
})();
window.access = access;
