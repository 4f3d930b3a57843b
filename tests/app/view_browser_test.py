#!/usr/bin/env python3
"""`sph view` in a real browser: Debian's headless Chromium driven by Selenium through ChromeDriver.

Usage: view_browser_test.py SPH_BINARY SOURCE_DIR (ctest passes both).

Runs a short 2D and 3D scene and a comparison (two neighbor modes side by side), writes their pages
with `sph view`, loads each from file:// and checks, through the page's own controls (mouse,
keyboard, selects), that it draws particles in the colors of the chosen map (not a blank canvas),
that scrubbing, stepping, play and pause change or keep the frame as they should, that choosing
another color field recolors the particles and the legend, that dragging orbits the 3D view (all
panels of a comparison together), and that a scene's obstacles are in the page's data and drawn
as solid gray boxes (2D and 3D). Saves a screenshot of each page to $SPH_TEST_OUTPUT, or to
view_browser/ in the current directory (ctest's binary directory). Fails, never skips, when
Chromium, ChromeDriver or Selenium is missing: `bash scripts/setup.sh` installs them.
"""

import base64
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

CHROMIUM = "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"
SETUP_HINT = "run `bash scripts/setup.sh` (installs chromium, chromium-driver and python3-selenium)"

# Selenium must never fetch a driver or a browser (no network on build machines): the driver and
# the browser are named explicitly below, and Selenium Manager is told to stay offline.
os.environ["SE_OFFLINE"] = "true"


def fail(message):
    print(f"FAIL: {message}", flush=True)
    sys.exit(1)


try:
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import Select
except ImportError as e:
    fail(f"cannot import selenium ({e}); {SETUP_HINT}")
for exe in (CHROMIUM, CHROMEDRIVER):
    if not os.access(exe, os.X_OK):
        fail(f"{exe} is missing; {SETUP_HINT}")

if len(sys.argv) != 3:
    fail("usage: view_browser_test.py SPH_BINARY SOURCE_DIR")
SPH, SRC = sys.argv[1], sys.argv[2]
OUT = os.environ.get("SPH_TEST_OUTPUT") or os.path.join(os.getcwd(), "view_browser")
os.makedirs(OUT, exist_ok=True)
WORK = tempfile.mkdtemp(prefix="sph_view_test_")
BACKGROUND = (247, 248, 250)  # the panels' background (viewer.css, viewer.js BG)
OBSTACLE = (196, 196, 196)  # an obstacle's fill in 2D, its faces' base color in 3D (viewer.js SOLID_RGB)

# Small scenes with an obstacle: a column collapsing onto a block (2D), a pool beside a pillar (3D).
OBSTACLE_SCENES = {
    "obstacle_2d": {
        "version": 1, "name": "obstacle_2d", "dimension": 2,
        "Configuration": {"particleRadius": 0.0075},
        "Container": {"start": [0, 0], "end": [0.6, 0.4]},
        "Obstacles": [{"start": [0.35, 0], "end": [0.45, 0.12]}],
        "FluidBlocks": [{"start": [0, 0], "end": [0.15, 0.3]}],
    },
    "obstacle_3d": {
        "version": 1, "name": "obstacle_3d", "dimension": 3,
        "Configuration": {"particleRadius": 0.01},
        "Container": {"start": [0, 0, 0], "end": [0.3, 0.3, 0.3]},
        "Obstacles": [{"start": [0.12, 0, 0.12], "end": [0.2, 0.2, 0.2]}],
        "FluidBlocks": [{"start": [0, 0, 0], "end": [0.1, 0.1, 0.3]}],
    },
}


def sph(*args, expect=0):
    r = subprocess.run([SPH, *args], capture_output=True, text=True)
    if r.returncode != expect:
        fail(f"sph {' '.join(args)} exited with {r.returncode} (expected {expect}):\n{r.stderr}")
    return r


def run_scene(scene, out, steps, every, *extra):
    sph("run", os.path.join(SRC, "scenes", "paper", scene), "-o", out, "--steps", str(steps), "--set",
        f"Configuration.outputEveryNSteps={every}", "--no-progress", *extra)


def page_data(html_file):
    with open(html_file, encoding="utf-8") as f:
        text = f.read()
    start = text.index('<script id="sph-data" type="application/json">')
    start = text.index(">", start) + 1
    return json.loads(text[start:text.index("</script>", start)])


def lut(data, name):
    for c in data["colors"]:
        if c["name"] == name:
            b = base64.b64decode(c["lut"])
            return [list(b[i:i + 3]) for i in range(0, len(b), 3)]
    fail(f"the page offers no color field {name!r}")


# Runs in the page: a summary of panel k's pixels. `lut` (256 RGB) given: how many drawn pixels
# have a color of the map or a shade of one (spheres are lit from one side: the shade scales the
# color). Returns [pixels, non-background pixels, of those near the map, checksum].
PIXELS_JS = """
const [k, bg, lut] = arguments;
const c = document.querySelectorAll('.panel canvas')[k];
const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
let drawn = 0, mapped = 0, sum = 0;
const near = new Map();
for (let i = 0; i < d.length; i += 4) {
  const r = d[i], g = d[i + 1], b = d[i + 2];
  sum = (sum * 31 + r * 7 + g * 3 + b) % 1000000007;
  if (Math.abs(r - bg[0]) + Math.abs(g - bg[1]) + Math.abs(b - bg[2]) < 12) continue;
  drawn++;
  if (!lut) continue;
  const key = (r << 16) | (g << 8) | b;
  let ok = near.get(key);
  if (ok === undefined) {
    ok = false;
    for (const m of lut) {
      // The closest shade s * m of the map's color m (spheres are lit from one side).
      const mm = m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
      const s = Math.max(0.25, Math.min(1.2, mm > 0 ? (r * m[0] + g * m[1] + b * m[2]) / mm : 1));
      if (Math.abs(r - s * m[0]) + Math.abs(g - s * m[1]) + Math.abs(b - s * m[2]) < 24) { ok = true; break; }
    }
    near.set(key, ok);
  }
  if (ok) mapped++;
}
return [d.length / 4, drawn, mapped, sum];
"""


# Runs in the page: the RGB of pixel (x, y) of panel k's canvas, and the canvas size.
PIXEL_JS = """
const [k, x, y] = arguments;
const c = document.querySelectorAll('.panel canvas')[k];
return [Array.from(c.getContext('2d').getImageData(x, y, 1, 1).data.slice(0, 3)), c.width, c.height];
"""

# Runs in the page: how many pixels of panel k are the obstacle's gray, or a shade of it
# (r = g = b between [lo, hi]).
GRAYS_JS = """
const [k, lo, hi] = arguments;
const c = document.querySelectorAll('.panel canvas')[k];
const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
let n = 0;
for (let i = 0; i < d.length; i += 4)
  if (d[i] === d[i + 1] && d[i + 1] === d[i + 2] && d[i] >= lo && d[i] <= hi) n++;
return [n, d.length / 4];
"""


def check_obstacles(page, scene):
    """The page's data holds the scene's obstacles, and the canvas shows them in gray."""
    dim = scene["dimension"]
    want = [{"lo": o["start"] + [0] * (3 - dim), "hi": o["end"] + [0] * (3 - dim)} for o in scene["Obstacles"]]
    got = page.data.get("obstacles")
    if got != want:
        fail(f"{page.name}: the page's data holds the obstacles {got!r}, expected {want!r}")
    if dim == 2:
        # The 2D camera (viewer.js projector): the container fills 92 % of the panel, centered.
        _, w, h = page.d.execute_script(PIXEL_JS, 0, 0, 0)
        lo, hi = page.data["box"]["lo"], page.data["box"]["hi"]
        s = 0.92 * min(w / (hi[0] - lo[0]), h / (hi[1] - lo[1]))
        o = want[0]
        ox, oy = 0.5 * (o["lo"][0] + o["hi"][0]), 0.5 * (o["lo"][1] + o["hi"][1])
        x = int(w / 2 + (ox - 0.5 * (lo[0] + hi[0])) * s)
        y = int(h / 2 - (oy - 0.5 * (lo[1] + hi[1])) * s)
        rgb = tuple(page.d.execute_script(PIXEL_JS, 0, x, y)[0])
        if rgb != OBSTACLE:
            fail(f"{page.name}: the obstacle's center ({x}, {y}) is {rgb}, expected its gray {OBSTACLE}")
        gray, total = page.d.execute_script(GRAYS_JS, 0, OBSTACLE[0], OBSTACLE[0])
        area = (o["hi"][0] - o["lo"][0]) * (o["hi"][1] - o["lo"][1]) * s * s
        if not 0.6 * area < gray < 1.1 * area:
            fail(f"{page.name}: {gray} pixels have the obstacle's gray, expected about {area:.0f}")
    else:
        # Its faces turned to the camera: shades of the gray, flat per face.
        gray, total = page.d.execute_script(GRAYS_JS, 0, int(0.5 * OBSTACLE[0]), OBSTACLE[0])
        if gray < 0.01 * total:
            fail(f"{page.name}: only {gray} of {total} pixels are in the obstacle's grays")
    print(f"  {page.name}: the obstacles are in the data and drawn ({gray} gray pixels)")


def make_driver():
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync",
                 "--disable-extensions", "--window-size=1400,900", "--force-device-scale-factor=1",
                 f"--user-data-dir={tempfile.mkdtemp(prefix='chromium_', dir=WORK)}"):
        options.add_argument(flag)
    try:
        return webdriver.Chrome(service=Service(executable_path=CHROMEDRIVER), options=options)
    except Exception as e:  # noqa: BLE001 - any failure to start is a failure of the test
        fail(f"cannot start headless Chromium through {CHROMEDRIVER}: {e}; {SETUP_HINT}")


class Page:
    def __init__(self, driver, html_file, name):
        self.d, self.name = driver, name
        self.data = page_data(html_file)
        driver.get("file://" + os.path.abspath(html_file))
        self.wait(lambda: driver.execute_script("return window.sphView ? window.sphView.renders : 0") >= 1,
                  "the page never drew (window.sphView.renders stays 0); JavaScript errors: " + self.errors())

    def errors(self):
        try:
            return str([e["message"] for e in self.d.get_log("browser") if e["level"] == "SEVERE"])
        except Exception:  # noqa: BLE001 - the log is a diagnostic only
            return "(no browser log)"

    def wait(self, cond, message, timeout=5.0):
        end = time.time() + timeout
        while time.time() < end:
            if cond():
                return
            time.sleep(0.05)
        fail(f"{self.name}: {message}")

    def renders(self):
        return self.d.execute_script("return window.sphView.renders")

    def settle(self, before, action="the action"):
        """Waits until the page drew again after an action (renders grew past `before`)."""
        self.wait(lambda: self.renders() > before, f"the page did not redraw after {action} "
                  f"(renders stayed {before}; frame readout {self.text('frame-label')!r})", timeout=30.0)
        time.sleep(0.05)

    def pixels(self, k=0, color=None):
        return self.d.execute_script(PIXELS_JS, k, list(BACKGROUND), lut(self.data, color) if color else None)

    def text(self, id_):
        return self.d.find_element(By.ID, id_).text

    def frame(self):
        label = self.text("frame-label")  # "frame 3 / 7"
        try:
            return int(label.split()[1]) - 1
        except (IndexError, ValueError):
            fail(f"{self.name}: the frame readout reads {label!r}; expected 'frame N / M'")

    def key(self, key):
        before = self.renders()
        ActionChains(self.d).send_keys(key).perform()
        return before

    def check_draws(self, color, min_fraction=0.02):
        total, drawn, mapped, _ = self.pixels(0, color)
        if drawn < min_fraction * total:
            fail(f"{self.name}: the canvas is nearly blank: {drawn} of {total} pixels differ from the background")
        if mapped < 0.5 * drawn:
            fail(f"{self.name}: only {mapped} of {drawn} drawn pixels have colors of the {color} map")
        print(f"  {self.name}: {drawn} of {total} pixels drawn, {mapped} in the colors of {color}")

    def screenshot(self, file_name):
        path = os.path.join(OUT, file_name)
        self.d.save_screenshot(path)
        print(f"  screenshot: {path}")


def check_controls(page, second_color):
    """Scrub, step, play/pause, color field; on a page whose first panel shows run 0."""
    d = page.d
    frames = page.data["runs"][0]["frames"]
    if page.frame() != 0:
        fail(f"{page.name}: the page opens at frame {page.frame() + 1}, expected the first")
    first_color = d.find_element(By.ID, "color").get_attribute("value")
    page.check_draws(first_color)
    _, _, _, sum0 = page.pixels()

    # Scrub: a click near the slider's right end shows a late frame.
    slider = d.find_element(By.ID, "slider")
    before = page.renders()
    ActionChains(d).move_to_element_with_offset(slider, int(slider.size["width"] * 0.45), 0).click().perform()
    page.settle(before, "a click on the slider")
    f = page.frame()
    if f < len(frames) // 2:
        fail(f"{page.name}: after clicking the slider near its end the readout shows frame {f + 1} of {len(frames)}")
    if page.pixels()[3] == sum0:
        fail(f"{page.name}: scrubbing to frame {f + 1} did not change the image")
    t_text = page.text("time-label")
    if f"{frames[f]['t']:.3f}" not in t_text:
        fail(f"{page.name}: the time readout {t_text!r} does not show frame {f + 1}'s time {frames[f]['t']}")

    # Keyboard: Home, then the right arrow steps one frame.
    page.settle(page.key(Keys.HOME), "Home")
    if page.frame() != 0:
        fail(f"{page.name}: Home did not go to the first frame")
    page.settle(page.key(Keys.ARROW_RIGHT), "the right arrow")
    if page.frame() != 1:
        fail(f"{page.name}: the right arrow went to frame {page.frame() + 1}, expected 2")
    page.settle(page.key(Keys.ARROW_LEFT), "the left arrow")

    # Play at 10 fps advances; pause stops.
    Select(d.find_element(By.ID, "speed")).select_by_value("10")
    d.find_element(By.ID, "play").click()
    page.wait(lambda: page.frame() >= 2, "play did not advance the frames within 5 s")
    d.find_element(By.ID, "play").click()
    stopped = page.frame()
    time.sleep(0.5)
    if page.frame() != stopped:
        fail(f"{page.name}: pause did not stop: frame {stopped + 1} became {page.frame() + 1}")
    # Space plays and pauses too.
    page.key(" ")
    page.wait(lambda: page.frame() != stopped, "space did not start playing")
    page.key(" ")
    stopped = page.frame()
    time.sleep(0.4)
    if page.frame() != stopped:
        fail(f"{page.name}: space did not pause")

    # Another color field: other pixel colors, another legend.
    # (Play may already have reached the last frame on a slow machine; End then has nothing to redraw.)
    at_end = page.frame() == len(frames) - 1
    before = page.key(Keys.END)
    if not at_end:
        page.settle(before, "End")
    if page.frame() != len(frames) - 1:
        fail(f"{page.name}: End went to frame {page.frame() + 1}, expected the last ({len(frames)})")
    legend = page.text("legend-label")
    _, _, _, sum1 = page.pixels()
    before = page.renders()
    Select(d.find_element(By.ID, "color")).select_by_value(second_color)
    page.settle(before, f"choosing the color field {second_color}")
    if page.text("legend-label") == legend:
        fail(f"{page.name}: the legend still reads {legend!r} after choosing {second_color}")
    if page.pixels()[3] == sum1:
        fail(f"{page.name}: choosing {second_color} did not change the image")
    if second_color != "initial_position":
        page.check_draws(second_color)
    print(f"  {page.name}: scrub, step, play, pause, color field ({first_color} -> {second_color}) work")


def drag(page, k, dx, dy):
    canvas = page.d.find_elements(By.CSS_SELECTOR, ".panel canvas")[k]
    before = page.renders()
    ActionChains(page.d).move_to_element(canvas).click_and_hold().move_by_offset(dx // 2, dy // 2) \
        .move_by_offset(dx - dx // 2, dy - dy // 2).release().perform()
    page.settle(before, "a drag on the canvas")


def check_bad_input():
    """One `sph: error:` line naming the problem, exit 2, no page written."""
    missing = os.path.join(WORK, "missing")
    r = sph("view", missing, expect=2)
    if "sph: error:" not in r.stderr or missing not in r.stderr:
        fail(f"sph view of a missing directory said: {r.stderr!r}")
    r = sph("view", os.path.join(WORK, "dam"), "--max-frames", "1", expect=2)
    if "--max-frames" not in r.stderr:
        fail(f"sph view --max-frames 1 said: {r.stderr!r}")
    r = sph("view", os.path.join(WORK, "dam"), "-o", os.path.join(WORK, "nodir", "x.html"), expect=2)
    if "sph: error:" not in r.stderr or os.path.exists(os.path.join(WORK, "nodir")):
        fail(f"sph view -o into a missing directory said: {r.stderr!r}")


def main():
    started = time.time()
    dam, block = os.path.join(WORK, "dam"), os.path.join(WORK, "block")
    run_scene("dam_break_2d.json", dam, 1200, 200)
    run_scene("block_3d.json", block, 600, 100)
    # A comparison: `sph compare` writes one run directory per mode and runs.txt naming them.
    # Where this build's compare does not (yet), two runs and a runs.txt make the same layout.
    cmp_dir = os.path.join(WORK, "compare")
    r = subprocess.run([SPH, "compare", os.path.join(SRC, "scenes", "paper", "block_3d.json"), "-o", cmp_dir,
                        "--steps", "300", "--modes", "standard,adaptive", "--set",
                        "Configuration.outputEveryNSteps=100", "--no-audit"], capture_output=True, text=True)
    if r.returncode != 0 or not os.path.isfile(os.path.join(cmp_dir, "runs.txt")):
        print("  note: sph compare wrote no run directories (no runs.txt); building the compare layout by hand")
        shutil.rmtree(cmp_dir, ignore_errors=True)
        for mode in ("standard", "adaptive"):
            run_scene("block_3d.json", os.path.join(cmp_dir, mode), 300, 100, "--neighbors", mode)
        with open(os.path.join(cmp_dir, "runs.txt"), "w") as f:
            f.write("standard\nadaptive\n")
    with open(os.path.join(cmp_dir, "runs.txt")) as f:
        labels = [line.strip() for line in f if line.strip()]
    for name, scene in OBSTACLE_SCENES.items():
        with open(os.path.join(WORK, f"{name}.json"), "w") as f:
            json.dump(scene, f)
        sph("run", os.path.join(WORK, f"{name}.json"), "-o", os.path.join(WORK, name), "--steps", "300", "--set",
            "Configuration.outputEveryNSteps=100", "--no-progress")
        sph("view", os.path.join(WORK, name))
    sph("view", dam)
    sph("view", block, "-o", os.path.join(WORK, "block.html"))
    sph("view", cmp_dir)
    check_bad_input()
    print(f"  runs and pages: {time.time() - started:.1f} s")

    driver = make_driver()
    try:
        driver.set_window_size(1400, 900)
        # 2D dam break: flat discs, pan only.
        page = Page(driver, os.path.join(dam, "view.html"), "2D dam break")
        check_controls(page, "density")
        page.screenshot("view_2d.png")

        # 3D block: orbit.
        page = Page(driver, os.path.join(WORK, "block.html"), "3D block")
        check_controls(page, "initial_position")
        page.screenshot("view_3d.png")
        _, _, _, s0 = page.pixels()
        drag(page, 0, 160, 40)
        if page.pixels()[3] == s0:
            fail("3D block: dragging across the canvas did not orbit the view")
        page.screenshot("view_3d_orbited.png")

        # Comparison: one panel per run, captioned, orbiting one orbits all.
        page = Page(driver, os.path.join(cmp_dir, "view.html"), "comparison")
        panels = driver.find_elements(By.CSS_SELECTOR, ".panel canvas")
        captions = [c.text for c in driver.find_elements(By.CSS_SELECTOR, ".panel .caption")]
        if len(panels) != len(labels):
            fail(f"comparison: {len(panels)} panels for {len(labels)} runs")
        if captions != labels:
            fail(f"comparison: the panels are captioned {captions}, expected {labels}")
        sums = []
        for k in range(len(panels)):
            total, drawn, _, s = page.pixels(k)
            if drawn < 0.02 * total:
                fail(f"comparison: panel {k + 1} ({labels[k]}) is nearly blank")
            sums.append(s)
        page.check_draws(driver.find_element(By.ID, "color").get_attribute("value"))
        drag(page, 0, -150, 30)
        for k in range(len(panels)):
            if page.pixels(k)[3] == sums[k]:
                fail(f"comparison: orbiting panel 1 did not move panel {k + 1} ({labels[k]})")
        page.key(Keys.END)
        time.sleep(0.2)
        page.screenshot("view_compare.png")
        print(f"  comparison: {len(panels)} panels ({', '.join(labels)}), orbiting together")

        # Obstacles: in the data, drawn solid.
        for name, scene in OBSTACLE_SCENES.items():
            page = Page(driver, os.path.join(WORK, name, "view.html"), name)
            check_obstacles(page, scene)
            page.screenshot(f"view_{name}.png")
    finally:
        driver.quit()
        shutil.rmtree(WORK, ignore_errors=True)
    print(f"PASS ({time.time() - started:.1f} s)")


if __name__ == "__main__":
    main()
