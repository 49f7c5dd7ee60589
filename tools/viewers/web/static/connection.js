// The page's one connection to the program: the debug protocol's commands over a WebSocket.
// Each text message sent is one command line, exactly as typed in telnet; answers come back in
// order as {"answer": TEXT}. "subscribe NAME" streams a representation: JSON messages
// {"topic", "context", "frame", "value"} or, for camera images, binary messages
// (4-byte big-endian header length, JSON header with the image's drawings, JPEG). "PlotNames" streams
// the plot names seen so far.

export class Connection {
  constructor(url) {
    this.url = url;
    this.pending = [];                 // resolvers of the commands sent, in order
    this.listeners = new Map();        // topic -> Set of callbacks
    this.rates = new Map();            // topic -> at most this many messages a second
    this.wanted = new Map();           // callback -> the rate it asked for (0: every message)
    this.events = new Map();           // "open" | "close" | "auth" -> Set of callbacks
    this.token = new URLSearchParams(location.search).get("token") || sessionStorage.getItem("tafel-token") || "";
    this.connected = false;
    this.open();
  }

  on(event, callback) {
    if (!this.events.has(event)) this.events.set(event, new Set());
    this.events.get(event).add(callback);
  }

  emit(event, ...args) {
    for (const callback of this.events.get(event) || []) callback(...args);
  }

  open() {
    const socket = new WebSocket(this.url);
    socket.binaryType = "arraybuffer";
    this.socket = socket;
    socket.onopen = async () => {
      this.connected = true;
      if (this.token) await this.ask(`auth ${this.token}`);
      const hello = await this.ask("hello");
      if (hello.startsWith("error: not authenticated")) { this.emit("auth"); return; }
      for (const topic of this.listeners.keys()) this.ask(this.subscribeLine(topic));
      this.emit("open", hello);
    };
    socket.onmessage = (event) => this.receive(event.data);
    socket.onclose = () => {
      const wasConnected = this.connected;
      this.connected = false;
      for (const { resolve } of this.pending.splice(0)) resolve("error: the connection to the program closed");
      if (wasConnected) this.emit("close");
      setTimeout(() => this.open(), 1000);
    };
  }

  async authenticate(token) {
    this.token = token;
    sessionStorage.setItem("tafel-token", token);
    const answer = await this.ask(`auth ${token}`);
    if (answer === "authenticated") {
      for (const topic of this.listeners.keys()) this.ask(this.subscribeLine(topic));
      this.emit("open", await this.ask("hello"));
    }
    return answer;
  }

  receive(data) {
    if (typeof data === "string") {
      const message = JSON.parse(data);
      if ("answer" in message) {
        const waiting = this.pending.shift();
        if (waiting) waiting.resolve(message.answer);
        return;
      }
      this.dispatch(message.topic, message);
      return;
    }
    const view = new DataView(data);
    const length = view.getUint32(0);
    const header = JSON.parse(new TextDecoder().decode(new Uint8Array(data, 4, length)));
    header.jpeg = new Blob([new Uint8Array(data, 4 + length)], { type: "image/jpeg" });
    this.dispatch(header.topic, header);
  }

  dispatch(topic, message) {
    for (const callback of this.listeners.get(topic) || []) {
      try { callback(message); } catch (error) { console.warn(`view of ${topic} failed:`, error); }
    }
  }

  // A command line's answer as text ("error: ..." included).
  ask(line) {
    if (!this.connected || this.socket.readyState !== WebSocket.OPEN) return Promise.resolve("error: not connected");
    return new Promise((resolve) => {
      this.pending.push({ resolve });
      this.socket.send(line);
    });
  }

  // A command's JSON answer; throws with the error text.
  async json(line) {
    const answer = await this.ask(line);
    if (answer.startsWith("error:")) throw new Error(answer);
    return JSON.parse(answer);
  }

  // The topic's value now, as a first message (a paused log sends nothing new): to every listener of
  // the topic, or to `only`.
  async current(topic, only) {
    if (topic === "PlotNames") return; // the program's own list, sent as names come (and once a second)
    const deliver = (message) => (only ? only(message) : this.dispatch(topic, message));
    if (topic.startsWith("CameraImage")) {
      const answer = await this.ask(`+image:get -name ${topic}`);
      if (answer.startsWith("error:")) return;
      const bytes = Uint8Array.from(atob(answer.trim()), (c) => c.charCodeAt(0));
      deliver({ topic, jpeg: new Blob([bytes], { type: "image/jpeg" }) });
      return;
    }
    const answer = await this.ask(`representation:print -name ${topic} -format json`);
    if (answer.startsWith("error:")) return;
    const value = JSON.parse(answer);
    for (const message of value.topic ? [value] : Object.values(value)) deliver(message);
  }

  subscribeLine(topic) {
    return this.rates.has(topic) ? `subscribe ${topic} -hz ${this.rates.get(topic)}` : `subscribe ${topic}`;
  }

  // Call back with every message of a topic; returns the function that stops it.
  // Options: {hz: N} asks for at most N messages a second (the newest each time), for all of the topic's listeners.
  subscribe(topic, options, callback) {
    if (typeof options === "function") { callback = options; options = {}; }
    const fresh = !this.listeners.has(topic);
    if (fresh) this.listeners.set(topic, new Set());
    this.listeners.get(topic).add(callback);
    this.wanted.set(callback, options.hz || 0);
    this.updateRate(topic, fresh);
    if (this.connected) this.current(topic, fresh ? null : callback);
    return () => {
      const set = this.listeners.get(topic);
      if (!set || !set.delete(callback)) return;
      this.wanted.delete(callback);
      if (set.size === 0) {
        this.listeners.delete(topic);
        this.rates.delete(topic);
        if (this.connected) this.ask(`unsubscribe ${topic}`);
      } else {
        this.updateRate(topic, false);
      }
    };
  }

  // The topic's rate is the highest its listeners ask for (none: every message); tell the program when it changes.
  updateRate(topic, fresh) {
    const asked = [...this.listeners.get(topic)].map((callback) => this.wanted.get(callback));
    const rate = asked.includes(0) ? 0 : Math.max(...asked);
    if (!fresh && rate === (this.rates.get(topic) || 0)) return;
    rate ? this.rates.set(topic, rate) : this.rates.delete(topic);
    if (this.connected) this.ask(this.subscribeLine(topic));
  }
}

// One argument of a command line: -name value, -name "value with spaces", or +name BASE64 for a value
// with a double quote or a line break (the protocol has no escapes; base64 carries any text).
export function arg(name, value) {
  const text = String(value);
  if (/^[^\s"]+$/.test(text)) return `-${name} ${text}`;
  if (!/["\n\r]/.test(text)) return `-${name} "${text}"`;
  const bytes = new TextEncoder().encode(text);
  return `+${name} ${btoa(String.fromCharCode(...bytes))}`;
}
