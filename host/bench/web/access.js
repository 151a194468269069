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
  //
  // One stream per browser, not per tab: a browser opens at most six connections to a host, and
  // a stream held by each of six tabs would leave none for the API (no state, no Stop). The tabs
  // of this bench elect a leader with a Web Lock (released when its tab closes, then the next tab
  // leads); the leader reads the stream and passes every event to the others on a
  // BroadcastChannel. A tab that joins reads the state and the views' snapshots through the API
  // (its `open`), then follows the leader's events. Without Web Locks (a page not served from a
  // loopback address is no secure context) each tab reads its own stream, as before.
  class LiveChannel extends EventTarget {
    constructor() {
      super();
      this.role = 'own';
      if (!('locks' in navigator) || typeof BroadcastChannel === 'undefined') {
        this.run(null);
        return;
      }
      const name = 'vibid-bench-live-' + token;  // per bench (token) and per origin (port)
      this.role = 'follower';
      const shared = new BroadcastChannel(name);
      shared.onmessage = m => { if (this.role === 'follower') this.emit(m.data, null); };
      navigator.locks.request(name, () => {
        this.role = 'leader';
        return this.run(shared);  // never settles: the lock is held for the tab's life
      });
      // Until it leads, a tab follows: the state now, then the leader's events.
      setTimeout(() => { if (this.role === 'follower') this.join(); }, 0);
    }

    // An event here, and to the other tabs when this tab reads the stream for them.
    emit(message, shared) {
      if (shared) shared.postMessage(message);
      if (message.kind === 'event') {
        this.dispatchEvent(new MessageEvent(message.type, {data: message.data}));
      } else if (message.kind === 'refused') {
        this.dispatchEvent(new CustomEvent('refused', {detail: message.detail}));
      } else {
        this.dispatchEvent(new Event(message.kind));
      }
    }

    // A follower's start: the board's state as the stream would have sent it first.
    async join() {
      try {
        const r = await fetch('/api/state', {headers: headers(), cache: 'no-store'});
        if (r.ok) this.emit({kind: 'event', type: 'state', data: await r.text()}, null);
      } catch (e) { /* the leader's next state will come */ }
      if (this.role === 'follower') this.emit({kind: 'open'}, null);
    }

    async run(shared) {
      for (;;) {
        let r;
        try {
          r = await fetch('/api/live', {headers: headers(), cache: 'no-store'});
        } catch (e) {
          this.emit({kind: 'error'}, shared);
          await sleep(1000);
          continue;
        }
        if (!r.ok) {
          const j = await r.json().catch(() => ({}));
          this.emit({kind: 'refused', detail: j.error || ('HTTP ' + r.status)}, shared);
          await sleep(3000);
          continue;
        }
        this.emit({kind: 'open'}, shared);
        try {
          await this.read(r.body.pipeThrough(new TextDecoderStream()).getReader(), shared);
        } catch (e) { /* the stream broke: reconnect */ }
        this.emit({kind: 'error'}, shared);
        await sleep(500);
      }
    }

    async read(reader, shared) {
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
          if (data.length) this.emit({kind: 'event', type, data: data.join('\n')}, shared);
        }
      }
    }
  }

  return {headers, hasToken: token !== '', LiveChannel};
})();
window.access = access;
