// Drives Foxglove Studio (served by scripts/viewer-screenshot.sh) in headless Chromium as a user
// would: "Open local file" -> the log, "Layouts -> Import from file" -> the layout, then a
// screenshot. The browser's file picker (window.showOpenFilePicker, which a headless browser
// cannot show) is answered with the file the script serves, by what the app asks for: a
// layout (.json) or a log. Exits 1, naming them and writing no picture, if the app reports a
// problem with the log.
// The PNG is written with a palette of 256 colours (upng-js), about a third of the size.
//
// usage: node shoot.mjs BASE_URL LOG_NAME LAYOUT_NAME OUT.png
import { writeFileSync } from "node:fs";
import { chromium } from "playwright-core";
import UPNG from "upng-js";

const [base, logName, layoutName, out] = process.argv.slice(2);
if (!out) {
  console.error("usage: node shoot.mjs BASE_URL LOG_NAME LAYOUT_NAME OUT.png");
  process.exit(2);
}
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium",
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync"],
});
const problems = [];
let shot;
try {
  const page = await browser.newPage({ viewport: { width: 1440, height: 900 } });
  page.on("console", (m) => {
    if (m.type() === "error" && m.text().startsWith("Player problem")) problems.push(m.text());
  });
  page.on("pageerror", (e) => problems.push(`page error: ${e}`));
  await page.addInitScript(([logName, layoutName]) => {
    // A file handle as the File System Access API gives one; its methods on the prototype so
    // that the app can keep it (structured clone) in its list of recent files.
    class Handle {
      constructor(name) {
        this.kind = "file";
        this.name = name;
      }
      async getFile() {
        const blob = await (await fetch(`/${this.name}`)).blob();
        return new File([blob], this.name);
      }
      async queryPermission() {
        return "granted";
      }
      async requestPermission() {
        return "granted";
      }
      async isSameEntry(other) {
        return other?.name === this.name;
      }
    }
    window.showOpenFilePicker = async (options) => {
      const wantsLayout = JSON.stringify(options?.types ?? []).includes(".json");
      return [new Handle(wantsLayout ? layoutName : logName)];
    };
  }, [logName, layoutName]);

  await page.goto(`${base}/index.html`);
  await page.getByText("Open local file").click({ timeout: 120_000 });
  await page.getByText(logName).first().waitFor({ timeout: 60_000 });

  await page.locator("button[title=Layouts]").click();
  await page.locator("button[title*=Import], button[aria-label*=Import]").first().click();
  await page.getByText(layoutName.replace(/\.json$/, "")).first().waitFor({ timeout: 30_000 });
  await page.locator("button[title=Layouts]").click(); // the sidebar closed: the panels only

  // Foxglove draws every plot from the whole log once it is read: let it settle.
  await page.waitForLoadState("networkidle");
  await page.waitForTimeout(10_000);
  await page.mouse.move(0, 899);
  shot = await page.screenshot();
} finally {
  await browser.close();
}
if (problems.length > 0) {
  console.error(`Foxglove reported ${problems.length} problem(s) with the log (no picture written):`);
  for (const p of problems) console.error(`  ${p.slice(0, 400)}`);
  process.exit(1);
}
const img = UPNG.decode(shot);
const rgba = UPNG.toRGBA8(img)[0];
writeFileSync(out, Buffer.from(UPNG.encode([rgba], img.width, img.height, 256)));
console.log(`wrote ${out}`);
