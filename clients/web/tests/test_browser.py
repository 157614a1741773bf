"""The pages in a real browser: Debian's headless Chromium driven by
Selenium (chromium-driver) against the whole stack on loopback (rig.py).
Writes a screenshot of each page into HJ_WEB_SCREENSHOTS (docs/web/).
Run by ctest (web_browser)."""

import os
import shutil
import tempfile
import time
import unittest

from hapticjam_client import Client, map_goal
from selenium import webdriver
from selenium.common.exceptions import TimeoutException
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select, WebDriverWait

from rig import TOKENS, Stack

SCREENSHOTS = os.environ.get("HJ_WEB_SCREENSHOTS", "")
CHROMIUM = os.environ.get("HJ_CHROMIUM", "/usr/bin/chromium")
CHROMEDRIVER = os.environ.get("HJ_CHROMEDRIVER", "/usr/bin/chromedriver")

# The canvas's pixels as counts: how many differ from the background, and a
# checksum that changes when the picture does.
CANVAS_SIGNATURE = """
const source = document.querySelector(arguments[0] + ' canvas');
const c = document.createElement('canvas');
c.width = source.width; c.height = source.height;
const g = c.getContext('2d');
g.drawImage(source, 0, 0);
const d = g.getImageData(0, 0, c.width, c.height).data;
let drawn = 0, sum = 0;
for (let k = 0; k < d.length; k += 4) {
  if (Math.abs(d[k] - 244) + Math.abs(d[k + 1] - 244) + Math.abs(d[k + 2] - 240) > 24) drawn++;
  sum = (sum * 31 + d[k] + 7 * d[k + 1] + 13 * d[k + 2]) % 1000000007;
}
return [drawn, sum, d.length / 4];
"""


def make_browser():
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync",
                 "--disable-dev-shm-usage", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                 "--window-size=1280,1000"):
        options.add_argument(flag)
    profile = tempfile.mkdtemp(prefix="hj_chromium_")
    options.add_argument("--user-data-dir=" + profile)
    return webdriver.Chrome(service=Service(CHROMEDRIVER), options=options), profile


class BrowserTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.stack = Stack()
        cls.browser, cls.profile = make_browser()

    @classmethod
    def tearDownClass(cls):
        cls.browser.quit()
        shutil.rmtree(cls.profile, ignore_errors=True)
        cls.stack.close()

    # -- helpers --

    def wait(self, condition, seconds=120, what="condition"):
        try:
            return WebDriverWait(self.browser, seconds, poll_frequency=0.1).until(lambda b: condition())
        except TimeoutException:
            errors = [e.text for e in self.browser.find_elements(By.CSS_SELECTOR, ".error") if e.text]
            raise AssertionError(f"timed out waiting for {what}; page errors: {errors}") from None

    def by_id(self, name):
        return self.browser.find_element(By.ID, name)

    def open(self, page, token):
        """Loads the page with `token` entered in the token form (kept in sessionStorage)."""
        self.browser.get(self.stack.url + "#" + page)
        self.wait(lambda: self.by_id("role").text, what="the role badge")
        field = self.by_id("token")
        field.clear()
        field.send_keys(token)
        self.by_id("token-form").submit()
        want = "preview" if token == TOKENS["preview"] else "operator or admin"
        self.wait(lambda: self.by_id("role").text == want, what=f"role {want}")

    def screenshot(self, name):
        if SCREENSHOTS:
            os.makedirs(SCREENSHOTS, exist_ok=True)
            self.browser.save_screenshot(os.path.join(SCREENSHOTS, name + ".png"))

    def queue_rows(self):
        """[(job id, the row's text)] of the queue table now (rows are redrawn at every change)."""
        return [(int(i), t) for i, t in self.browser.execute_script(
            "return [...document.querySelectorAll('#queue-body tr')].map((r) => [r.id.slice(4), r.innerText]);")]

    def signature(self, selector):
        return self.browser.execute_script(CANVAS_SIGNATURE, selector)

    def plan_volcano(self):
        self.open("plan?map=volcano&rows=3&cols=4&segments=2", TOKENS["operator"])
        # The start button is enabled once the server's maps are in the form.
        self.wait(lambda: self.by_id("plan-start").is_enabled() and self.by_id("plan-map").get_attribute("value"),
                  what="the plan form filled")
        self.by_id("plan-start").click()
        self.wait(lambda: self.by_id("plan-result").is_displayed(), what="the plan's result")

    # -- tests, in name order: the plan is made first and submitted later --

    def test_1_plan_streams_a_dem_in_3d_with_the_apis_correlation(self):
        self.plan_volcano()
        count = int(self.by_id("plan-snapshots").text)
        self.assertGreaterEqual(count, 5)
        kind = self.by_id("plan-view").get_attribute("data-kind")
        print(f"plan view drawn with {kind}; {count} snapshots")
        # The canvas drew, and differently for an early and the last streamed snapshot.
        scrub = self.by_id("plan-scrub")
        pictures = []
        for k in (1, count):
            self.browser.execute_script("arguments[0].value = arguments[1];"
                                        "arguments[0].dispatchEvent(new Event('input'));", scrub, str(k))
            pictures.append(self.signature("#plan-view"))
        for drawn, _, total in pictures:
            self.assertGreater(drawn, total // 20)
        self.assertNotEqual(pictures[0][1], pictures[1][1])
        # The final picture, the goal beside it; the correlation is the API's own.
        self.browser.execute_script("arguments[0].value = arguments[0].max;"
                                    "arguments[0].dispatchEvent(new Event('input'));", scrub)
        shown = float(self.by_id("plan-correlation").get_attribute("data-value"))
        with Client(self.stack.grpc_address, token=TOKENS["preview"]) as client:
            result, _ = client.plan(map_goal("volcano"), 3, 4, segments=2, timeout=120)
        self.assertTrue(result.HasField("correlation"))
        self.assertEqual(shown, result.correlation)
        self.assertIn(f"{result.correlation:.4f}", self.by_id("plan-correlation").text)
        self.screenshot("plan")

    def test_2_device_page_hides_the_controls_from_a_preview_token(self):
        self.open("device", TOKENS["preview"])
        self.wait(lambda: self.browser.find_elements(By.CSS_SELECTOR, "#device-status span"), what="device status")
        for control in ("submit-plan", "emergency-stop", "resume-queue"):
            self.assertEqual(self.browser.find_elements(By.ID, control), [], control)
        self.assertIn("preview role", self.by_id("device-controls").text)

    def test_3_an_operator_submits_the_plan_and_sees_it_in_the_queue(self):
        self.open("device", TOKENS["operator"])
        submit = self.wait(lambda: self.browser.find_elements(By.ID, "submit-plan"), what="the submit button")[0]
        self.wait(lambda: submit.is_enabled(), what="a current plan")
        self.by_id("job-name").send_keys("web: volcano")
        submit.click()
        job_id, text = self.wait(lambda: [r for r in self.queue_rows() if "web: volcano" in r[1]],
                                 what="the job in the queue")[0]
        self.assertIn("alice", text)
        with Client(self.stack.grpc_address, token=TOKENS["operator"]) as client:
            job = client.wait_for_job(job_id, timeout=120)
        self.assertEqual(job.name, "web: volcano")
        self.wait(lambda: any(i == job_id and "done" in t for i, t in self.queue_rows()), what="the job done on the page")
        self.screenshot("device")

    def test_4_zoom_into_two_regions_and_back(self):
        self.open("zoom", TOKENS["preview"])
        canvas = self.by_id("zoom-canvas")
        self.wait(lambda: "north up" in self.by_id("zoom-caption").text, what="the map drawn")
        self.assertGreater(self.signature("figure.map")[0], 1000)
        width, height = canvas.size["width"], canvas.size["height"]
        for (x0, y0, x1, y1) in ((0.2, 0.2, 0.7, 0.7), (0.35, 0.35, 0.6, 0.6)):
            count = len(self.browser.find_elements(By.CSS_SELECTOR, "#zoom-history button"))
            # Offsets are from the canvas's centre.
            (ActionChains(self.browser).move_to_element_with_offset(canvas, (x0 - 0.5) * width, (y0 - 0.5) * height)
             .click_and_hold().move_by_offset((x1 - x0) * width / 2, (y1 - y0) * height / 2)
             .move_by_offset((x1 - x0) * width / 2, (y1 - y0) * height / 2).release().perform())
            self.wait(lambda: len(self.browser.find_elements(By.CSS_SELECTOR, "#zoom-history button")) > count or
                      self.by_id("zoom-error").is_displayed(), what="the region's preview")
            self.assertFalse(self.by_id("zoom-error").is_displayed(), self.by_id("zoom-error").text)
        self.assertEqual(len(self.browser.find_elements(By.CSS_SELECTOR, "#zoom-history button")), 2)
        self.browser.find_elements(By.CSS_SELECTOR, "#zoom-history button")[0].click()
        self.assertIn("instant", self.by_id("zoom-source").text)
        self.assertGreater(self.signature("#zoom-view")[0], 1000)
        self.screenshot("zoom")

    def test_5_workbench_compares_a_dataset_and_shows_its_report(self):
        self.open("workbench", TOKENS["preview"])
        self.wait(lambda: Select(self.by_id("bench-dataset")).options, what="the datasets")
        self.browser.find_element(By.CSS_SELECTOR, "[data-run=compare]").click()
        self.wait(lambda: self.by_id("bench-result").is_displayed() or self.by_id("bench-error").is_displayed(),
                  what="the comparison")
        self.assertFalse(self.by_id("bench-error").is_displayed(), self.by_id("bench-error").text)
        rmse = self.browser.find_element(By.CSS_SELECTOR, "[data-figure=RMSE]").text
        self.assertTrue(rmse.endswith("mm"), rmse)
        self.assertTrue(self.by_id("bench-report").is_displayed())
        self.assertTrue(self.browser.find_elements(By.CSS_SELECTOR, "#bench-progress .stage"))
        self.screenshot("workbench")

    def test_6_fit_needs_an_operator_and_the_page_says_so(self):
        self.open("workbench", TOKENS["preview"])
        self.wait(lambda: Select(self.by_id("bench-dataset")).options, what="the datasets")
        self.browser.find_element(By.CSS_SELECTOR, "[data-run=fit]").click()
        self.wait(lambda: self.by_id("bench-error").is_displayed(), what="the refusal")
        self.assertIn("PERMISSION_DENIED", self.by_id("bench-error").text)
        self.assertIn("needs operator", self.by_id("bench-error").text)

    def test_7_a_folder_chosen_in_the_browser_is_uploaded_and_compared(self):
        self.open("workbench", TOKENS["preview"])
        # Chromium takes a folder path for a webkitdirectory input.
        self.by_id("bench-folder").send_keys(self.stack.dataset)
        self.assertTrue(self.browser.find_element(By.CSS_SELECTOR, "input[name=dataset-source][value=upload]").is_selected())
        self.browser.find_element(By.CSS_SELECTOR, "[data-run=compare]").click()
        self.wait(lambda: self.by_id("bench-result").is_displayed() or self.by_id("bench-error").is_displayed(),
                  what="the comparison")
        self.assertFalse(self.by_id("bench-error").is_displayed(), self.by_id("bench-error").text)
        self.assertIn("demo-two", self.browser.execute_script("return document.getElementById('bench-report').srcdoc"))


if __name__ == "__main__":
    unittest.main(verbosity=2)
