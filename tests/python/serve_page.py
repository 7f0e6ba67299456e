#!/usr/bin/env python3
"""`pneumo serve`'s page in a real browser: headless Chromium driven by Selenium
opens the page (the scene's ports listed), waits for the first equilibrium, clicks the skin on the
body's view to place a port,
waits for the laparoscope's view, moves the pressure slider down, waits for the view to change and
the status to report the new pressure, paints a region on the body, ranks the ports for the target
within it, places one at the best candidate, and saves a screenshot.

Usage: serve_page.py PNEUMO SCENE SCRATCH_DIR [SCREENSHOT]
Exit 0 when every step held, 1 when one did not (the step is printed), 77 when Chromium or its
driver cannot start here (the caller skips, saying so).
"""
import re
import subprocess
import sys
import time

try:
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.keys import Keys
except ImportError as e:
    print(f"skip: python3-selenium is missing ({e}); scripts/install_deps.sh installs it")
    sys.exit(77)

pneumo, scene, scratch = sys.argv[1], sys.argv[2], sys.argv[3]
screenshot = sys.argv[4] if len(sys.argv) > 4 else None


def fail(step):
    print("FAILED: " + step)
    sys.exit(1)


def wait_for(what, condition, seconds):
    end = time.time() + seconds
    while time.time() < end:
        value = condition()
        if value:
            return value
        time.sleep(0.25)
    fail(what)


server = subprocess.Popen([pneumo, "-q", "serve", scene, "--port", "0", "--out", scratch + "/serve_out"],
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
driver = None
try:
    line = server.stdout.readline()
    m = re.search(r"http://[^:]+:(\d+)/", line)
    if not m:
        fail("the server printed its address (got: %r)" % line)
    url = f"http://127.0.0.1:{m.group(1)}/"

    options = webdriver.ChromeOptions()
    for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
              "--window-size=1400,1100", f"--user-data-dir={scratch}/profile", "--force-device-scale-factor=1"):
        options.add_argument(a)
    options.binary_location = "/usr/bin/chromium"
    try:
        driver = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)
    except Exception as e:  # noqa: BLE001 - any failure to start the browser is a skip, said why
        print(f"skip: Chromium does not start here: {str(e).splitlines()[0] if str(e) else e!r}")
        sys.exit(77)
    driver.set_page_load_timeout(60)
    driver.get(url)
    status = driver.find_element(By.ID, "status")
    wait_for("the first equilibrium (status 'converged at 12.0 mmHg')",
             lambda: status.text.startswith("converged at 12.0"), 240)

    exterior = driver.find_element(By.ID, "exterior")
    wait_for("the body's view", lambda: driver.execute_script(
        "return arguments[0].complete && arguments[0].naturalWidth > 0", exterior), 60)
    ports_before = len(driver.find_elements(By.CSS_SELECTOR, "#port-list button"))   # the scene's own
    exterior.click()   # the middle of the anterior view: the skin in front of the abdomen
    wait_for("a port placed on the skin", lambda: len(driver.find_elements(
        By.CSS_SELECTOR, "#port-list button")) == ports_before + 1, 60)
    scope = driver.find_element(By.ID, "scope")
    view_settled = ("return !state.viewBusy && !state.viewAgain && state.selected === arguments[1] && "
                    "arguments[0].complete && arguments[0].naturalWidth === 480")
    wait_for("the laparoscope's view from the new port", lambda: driver.execute_script(view_settled, scope, ports_before), 60)
    before = scope.screenshot_as_png

    slider = driver.find_element(By.ID, "pressure")
    slider.click()
    for _ in range(20):   # from the middle down to 6 mmHg, one step per key, then the change event
        if int(slider.get_attribute("value")) <= 6:
            break
        slider.send_keys(Keys.ARROW_LEFT)
    pressure = int(slider.get_attribute("value"))
    if pressure >= 12:
        fail("the pressure slider moved down (it reads %d)" % pressure)
    wait_for(f"the status at {pressure}.0 mmHg, converged",
             lambda: status.text.startswith(f"converged at {pressure}.0"), 240)
    wait_for("the laparoscope's view changed with the pressure",
             lambda: driver.execute_script(view_settled, scope, ports_before) and scope.screenshot_as_png != before, 60)

    # Port ranking within a region painted by dragging on the body's view (a drag places no port):
    # the target's candidates scored on the skin, the best listed; a click on the first places a
    # port there.
    ports_now = len(driver.find_elements(By.CSS_SELECTOR, "#port-list button"))
    ActionChains(driver).move_to_element_with_offset(exterior, -200, -150).click_and_hold() \
        .move_by_offset(400, 280).release().perform()
    wait_for("the painted region shown", lambda: driver.find_element(By.ID, "region").is_displayed(), 10)
    time.sleep(0.5)
    if len(driver.find_elements(By.CSS_SELECTOR, "#port-list button")) != ports_now:
        fail("a drag on the body paints a region and places no port")
    driver.find_element(By.ID, "rank").click()
    wait_for("the ranked ports listed", lambda: driver.find_elements(By.CSS_SELECTOR, "#ranked li"), 120)
    if not driver.find_element(By.ID, "heat").is_selected():
        fail("the port map shown on the body's view")
    driver.find_elements(By.CSS_SELECTOR, "#ranked li")[0].click()
    wait_for("a port placed at the best candidate", lambda: len(driver.find_elements(
        By.CSS_SELECTOR, "#port-list button")) == ports_now + 1, 60)
    wait_for("the laparoscope's view from the best candidate",
             lambda: driver.execute_script(view_settled, scope, ports_now), 60)
    wait_for("the body's view with the map", lambda: driver.execute_script(
        "return arguments[0].complete && arguments[0].naturalWidth > 0 && arguments[0].src.includes('heat=1')",
        exterior), 60)
    if screenshot:
        driver.save_screenshot(screenshot)
    print(f"ok: port placed, view changed, ports ranked and one placed, status '{status.text}'")
finally:
    if driver:
        driver.quit()
    server.terminate()
    try:
        server.wait(timeout=30)
    except subprocess.TimeoutExpired:
        server.kill()
        fail("the server stopped within 30 s of SIGTERM")
    if server.returncode not in (0, -15):
        fail(f"the server's exit after SIGTERM: {server.returncode}")
