// Drives an explorer page (hypersynth --html) in headless Chromium and prints what it shows,
// as one JSON document on standard output, for tests/explorer_browser.rs to compare with the
// command line. It asserts nothing itself.
//
//   node explorer.mjs COMMAND PAGE.html [ARGUMENTS...]
//
//   inspect PAGE X,Y...        click each robot cell (adversary and automata as in h0): its table
//   run PAGE                   step through the seeded run with the "step forward" button
//   play PAGE X,Y...           play the adversary, one click per cell: the page's play log
//   open PAGE                  what the page shows once loaded: title, heading, dialogs, errors
//   measure PAGE X,Y...        the page's load time and each click's latency (place the adversary)
//   screenshot PAGE OUT.png [explore|run|play] [X,Y...]
//   geometry PAGE X,Y          the board's texts and marks (boxes) in both fills, in the slice
//                              of h0 and after each "visit" button; the hatched cells, the value
//                              scale; and how the decision table of cell X,Y fits the window
//
// The window is 1500 pixels wide, or $VIEWPORT_WIDTH.
// Chromium: $CHROMIUM or /usr/bin/chromium, with a fresh profile and no network services.

import { chromium } from 'playwright-core';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const [command, pagePath, ...rest] = process.argv.slice(2);
if (!command || !pagePath) {
  console.error('usage: node explorer.mjs COMMAND PAGE.html [ARGUMENTS...]');
  process.exit(2);
}

const cells = (list) => list.map((text) => text.split(',').map(Number));

async function withPage(body) {
  const profile = mkdtempSync(join(tmpdir(), 'hypersynth-chromium-'));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    headless: true,
    viewport: { width: Number(process.env.VIEWPORT_WIDTH || 1500), height: 1000 },
    args: [
      '--no-sandbox', '--disable-gpu', '--disable-background-networking',
      '--disable-component-update', '--disable-sync', '--no-first-run', '--disable-quic',
    ],
  });
  try {
    const page = context.pages()[0] || await context.newPage();
    const seen = { dialogs: [], errors: [], console: [], requests: [] };
    page.on('dialog', async (dialog) => {
      seen.dialogs.push(dialog.message());
      await dialog.dismiss();
    });
    page.on('pageerror', (error) => seen.errors.push(error.message));
    page.on('console', (message) => seen.console.push(message.text()));
    page.on('request', (request) => {
      if (!request.url().startsWith('file:') && !request.url().startsWith('data:')) {
        seen.requests.push(request.url());
      }
    });
    const started = Date.now();
    await page.goto(pathToFileURL(resolve(pagePath)).href);
    await page.waitForSelector('body[data-ready="true"]', { timeout: 60000 });
    const loadMs = Date.now() - started;
    return await body(page, seen, loadMs);
  } finally {
    await context.close();
    rmSync(profile, { recursive: true, force: true });
  }
}

const cell = (page, [x, y]) => page.locator(`rect.cell[data-x="${x}"][data-y="${y}"]`);

// The decision table the page shows.
async function decision(page) {
  return page.evaluate(() => {
    const box = document.getElementById('decision');
    const value = (node) => (node.dataset.value === 'inf' ? null : Number(node.dataset.value));
    const head = box.querySelector('p.state');
    if (!head) return { message: box.textContent };
    const numbers = head.querySelectorAll('[data-value]');
    const actions = [];
    for (const tr of box.querySelectorAll('tbody tr')) {
      const tds = tr.querySelectorAll('td');
      if (tr.classList.contains('action')) {
        actions.push({
          action: tds[0].textContent,
          value: value(tds[1]),
          expected_moves: value(tds[2]),
          chosen: tr.classList.contains('chosen'),
          outcomes: [],
        });
      } else {
        actions[actions.length - 1].outcomes.push({
          state: tds[1].textContent,
          label: tds[2].textContent,
          probability: value(tds[3]),
          value: value(tds[4]),
          shown: [tds[3].textContent, tds[4].textContent],
        });
      }
    }
    const chosen = box.querySelector('.chosen-action').textContent;
    return {
      state: head.querySelector('.name').textContent,
      label: head.querySelector('.label').textContent,
      value: value(numbers[0]),
      expected_moves: value(numbers[1]),
      actions,
      chosen: chosen === '-' ? null : chosen,
    };
  });
}

const commands = {
  async inspect(page) {
    const out = [];
    for (const xy of cells(rest)) {
      await cell(page, xy).click();
      out.push({ cell: xy, table: await decision(page) });
    }
    return out;
  },

  async run(page) {
    await page.click('#tab-run');
    const out = [];
    const last = Number(await page.getAttribute('#run-slider', 'max'));
    for (let k = 0; k <= last; k++) {
      if (k > 0) await page.click('#run-forward');
      out.push(await page.evaluate(() => {
        const row = document.querySelector('#run-table tr.current');
        const text = (name) => row.querySelector(name).textContent;
        const shape = (selector) => {
          const node = document.querySelector(selector);
          return node.getAttribute('visibility') === 'hidden' ? null : node.getBoundingClientRect().toJSON();
        };
        return {
          step: Number(document.getElementById('run-position').dataset.step),
          state: text('.run-state'),
          label: text('.run-label'),
          action: text('.run-action'),
          committed: text('.run-committed'),
          slice: document.getElementById('slice').textContent,
          robot: shape('#board circle[r]'),
        };
      }));
    }
    // And back again: the first step is shown as at first.
    for (let k = last; k > 0; k--) await page.click('#run-back');
    const back = Number(await page.evaluate(() => document.getElementById('run-position').dataset.step));
    return { steps: out, back };
  },

  async play(page) {
    await page.click('#tab-play');
    const log = () => page.evaluate(() => [...document.querySelectorAll('#play-table tbody tr')].map((tr) => ({
      step: Number(tr.cells[0].textContent),
      state: tr.querySelector('.play-state').textContent,
      answer: tr.querySelector('.play-answer').firstChild ? tr.querySelector('.play-answer').firstChild.textContent : '',
      warning: tr.querySelector('.play-warning') ? tr.querySelector('.play-warning').textContent : null,
    })));
    const clicked = [];
    for (const xy of cells(rest)) {
      const over = await page.getAttribute('#play-prompt', 'data-over');
      if (over === 'true') break;
      await cell(page, xy).click();
      clicked.push(xy);
    }
    return {
      clicked,
      log: await log(),
      prompt: await page.textContent('#play-prompt'),
    };
  },

  async open(page, seen) {
    return {
      title: await page.title(),
      heading: await page.textContent('#title'),
      report: await page.textContent('#report'),
      status: await page.textContent('#status'),
      injected: await page.evaluate(() => window.injected === undefined ? null : String(window.injected)),
      scripts: await page.evaluate(() => document.scripts.length),
      dialogs: seen.dialogs,
      errors: seen.errors,
      requests: seen.requests,
    };
  },

  async measure(page, seen, loadMs) {
    await page.click('#click-place');
    const clicks = [];
    for (const xy of cells(rest)) {
      const started = Date.now();
      await cell(page, xy).click();
      await page.waitForFunction(([x, y]) => document.getElementById('slice').textContent
        .startsWith(`Adversary at (${x},${y})`), xy);
      clicks.push({
        cell: xy,
        inPageMs: Number(await page.evaluate(() => document.body.dataset.lastUpdateMs)),
        roundTripMs: Date.now() - started,
      });
    }
    await page.click('#click-inspect');
    const [x, y] = cells(rest)[0];
    await cell(page, [x === 0 ? 1 : x - 1, y]).click();
    const inspectMs = Number(await page.evaluate(() => document.body.dataset.lastUpdateMs));
    return { loadMs, clicks, inspectMs, errors: seen.errors };
  },

  async geometry(page, seen) {
    const board = () => page.evaluate(() => {
      const box = (node) => {
        const b = node.getBBox();
        return [b.x, b.y, b.x + b.width, b.y + b.height];
      };
      const shown = (node) => node.getAttribute('visibility') !== 'hidden'
        && (node.tagName !== 'path' || (node.getAttribute('d') || '') !== '')
        && (node.tagName !== 'text' || node.textContent !== '');
      const svg = document.getElementById('board');
      const texts = [...svg.querySelectorAll('text.code, text.prop')].filter(shown)
        .map((node) => ({ text: node.textContent, box: box(node) }));
      const marks = [...svg.querySelectorAll('path.mark, path.arrowhead, circle[r], path[fill="#E69F00"]')]
        .filter(shown).map((node) => box(node));
      const cells = [...svg.querySelectorAll('rect.cell')].map((rect) => ({
        cell: [Number(rect.dataset.x), Number(rect.dataset.y)],
        fill: rect.getAttribute('fill'),
        title: rect.querySelector('title').textContent,
      }));
      const hatched = [...svg.querySelectorAll('path.hatch')]
        .map((rect, i) => [rect.getAttribute('visibility') === 'visible', i])
        .filter(([v]) => v).map(([, i]) => cells[i].cell);
      const bar = [...document.querySelectorAll('#legend li.scale rect[height="6.4"]')]
        .map((rect) => rect.getAttribute('fill'));
      const ticks = [...document.querySelectorAll('#legend .ticks span')].map((t) => t.textContent);
      return {
        slice: document.getElementById('slice').textContent, texts, marks, cells, hatched,
        bar, ticks,
      };
    });
    const views = [];
    const buttons = await page.$$eval('#visits button', (list) => list.map((b) => b.textContent));
    for (const shading of ['labels', 'values']) {
      await page.click(`#shade-${shading}`);
      await page.click('#reset-slice');
      views.push({ shading, visited: null, ...await board() });
      for (const name of buttons) {
        await page.click('#reset-slice');
        await page.click(`#visits button:text-is("${name}")`);
        views.push({ shading, visited: name, ...await board() });
      }
    }
    await page.click('#shade-labels');
    await page.click('#reset-slice');
    await cell(page, cells(rest)[0]).click();
    const table = await page.evaluate(() => {
      const t = document.querySelector('#decision table');
      const root = document.documentElement;
      const wrapped = [...t.querySelectorAll('td.outcome-state, td.outcome-label')].filter((td) => {
        const range = document.createRange();
        range.selectNodeContents(td);
        return new Set([...range.getClientRects()].map((r) => Math.round(r.top))).size > 1;
      }).map((td) => td.textContent);
      return {
        right: t.getBoundingClientRect().right,
        window: root.clientWidth,
        scrollWidth: root.scrollWidth,
        wrapped,
      };
    });
    return { views, table, errors: seen.errors };
  },

  async screenshot(page, seen) {
    const [out, mode, ...clicks] = rest;
    if (mode && mode !== 'explore') await page.click(`#tab-${mode}`);
    for (const xy of cells(clicks)) {
      if (mode === 'run') {
        for (let k = 0; k < xy[0]; k++) await page.click('#run-forward');
      } else {
        await cell(page, xy).click();
      }
    }
    await page.screenshot({ path: out, fullPage: true });
    return { out, errors: seen.errors };
  },
};

const run = commands[command];
if (!run) {
  console.error(`unknown command ${command}`);
  process.exit(2);
}
const result = await withPage(run);
process.stdout.write(JSON.stringify(result) + '\n');
