// The app root as Foxglove Studio's web package rendered it (studio-base's `App` with the
// local-file data sources), with the two stores the web package kept in the browser
// (settings, layouts) kept in memory: each screenshot starts from a fresh app.
"use strict";
(async function main() {
  const S = self;
  class MemoryAppConfiguration {
    constructor() {
      this.values = new Map();
      this.listeners = new Map();
    }
    get(key) {
      return this.values.get(key);
    }
    async set(key, value) {
      this.values.set(key, value);
      for (const cb of this.listeners.get(key) ?? []) cb(value);
    }
    addChangeListener(key, cb) {
      if (!this.listeners.has(key)) this.listeners.set(key, new Set());
      this.listeners.get(key).add(cb);
    }
    removeChangeListener(key, cb) {
      this.listeners.get(key)?.delete(cb);
    }
  }
  class MemoryLayoutStorage {
    constructor() {
      this.spaces = new Map();
    }
    space(ns) {
      if (!this.spaces.has(ns)) this.spaces.set(ns, new Map());
      return this.spaces.get(ns);
    }
    async list(ns) {
      return [...this.space(ns).values()];
    }
    async get(ns, id) {
      return this.space(ns).get(id);
    }
    async put(ns, layout) {
      this.space(ns).set(layout.id, layout);
      return layout;
    }
    async delete(ns, id) {
      this.space(ns).delete(id);
    }
    async importLayouts({ fromNamespace, toNamespace }) {
      for (const l of this.space(fromNamespace).values()) this.space(toNamespace).set(l.id, l);
      this.space(fromNamespace).clear();
    }
  }
  S.installDevtoolsFormatters();
  S.overwriteFetch();
  await S.waitForFonts();
  await S.initI18n();
  S.ReactDOM.render(
    S.React.createElement(S.App, {
      deepLinks: [location.href],
      appConfiguration: new MemoryAppConfiguration(),
      dataSources: [new S.McapLocalDataSourceFactory(), new S.RemoteDataSourceFactory()],
      layoutStorage: new MemoryLayoutStorage(),
      extensionLoaders: [new S.IdbExtensionLoader("org"), new S.IdbExtensionLoader("local")],
      enableLaunchPreferenceScreen: false,
      enableGlobalCss: true,
    }),
    document.getElementById("root"),
  );
})().catch((err) => {
  console.error("app failed to start:", err);
});
