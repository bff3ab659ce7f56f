// The explorer page (see crates/hypersynth/src/explorer/mod.rs for the data). Everything the
// data names (files, formulas, tasks, states) is written with textContent or as SVG text
// nodes, never parsed as markup; nothing here evaluates text.
'use strict';
(function () {
  const SVG = 'http://www.w3.org/2000/svg';
  const $ = (id) => document.getElementById(id);
  const status = $('status');

  function fail(message) {
    status.textContent = message;
    status.className = 'error';
  }

  // The data: JSON, compressed with zlib, in base 64.
  async function load() {
    if (typeof DecompressionStream === 'undefined') {
      throw new Error('this browser has no DecompressionStream');
    }
    const binary = atob($('data').textContent.trim());
    const bytes = new Uint8Array(binary.length);
    for (let i = 0; i < binary.length; i++) bytes[i] = binary.charCodeAt(i);
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('deflate'));
    return JSON.parse(await new Response(stream).text());
  }

  // A table of base-64 codes (the exported controller's format: `width` digits per entry,
  // `width` dots for a missing one, `~N~` for a run of N missing ones), read once into an
  // array: entry i, or -1 for none.
  const DIGITS = '0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz-_';
  const DIGIT = new Int8Array(128).fill(-1);
  for (let i = 0; i < 64; i++) DIGIT[DIGITS.charCodeAt(i)] = i;
  const DOT = 46;
  const TILDE = 126;
  function reader(table) {
    if (!table) return null;
    const width = table.width;
    const codes = table.codes;
    const digits = (from, to) => {
      let value = 0;
      for (let k = from; k < to; k++) {
        const digit = DIGIT[codes.charCodeAt(k)];
        if (digit < 0) throw new Error('a malformed table at character ' + k);
        value = value * 64 + digit;
      }
      return value;
    };
    let length = 0;
    for (let at = 0; at < codes.length;) {
      if (codes.charCodeAt(at) === TILDE) {
        const end = codes.indexOf('~', at + 1);
        length += digits(at + 1, end);
        at = end + 1;
      } else {
        length += 1;
        at += width;
      }
    }
    // Five digits are 30 bits: such entries fit 32-bit integers, wider ones need doubles.
    const entries = (width <= 5 ? new Int32Array(length) : new Float64Array(length)).fill(-1);
    let i = 0;
    for (let at = 0; at < codes.length;) {
      const c = codes.charCodeAt(at);
      if (c === TILDE) {
        const end = codes.indexOf('~', at + 1);
        i += digits(at + 1, end);
        at = end + 1;
      } else {
        if (c !== DOT) entries[i] = digits(at, at + width);
        i += 1;
        at += width;
      }
    }
    return (k) => (k >= 0 && k < length ? entries[k] : -1);
  }

  function element(tag, attributes, parent) {
    const node = document.createElementNS(SVG, tag);
    for (const name in attributes) node.setAttribute(name, attributes[name]);
    if (parent) parent.appendChild(node);
    return node;
  }

  function html(tag, text, parent, className) {
    const node = document.createElement(tag);
    if (text !== undefined && text !== null) node.textContent = text;
    if (className) node.className = className;
    if (parent) parent.appendChild(node);
    return node;
  }

  // A value or probability as the text report prints it: six decimals without trailing
  // zeros (300, 294.021143, 0.5).
  function fixed(value, digits) {
    if (value === null) return 'infinite';
    const text = value.toFixed(digits).replace(/\.?0+$/, '');
    return text === '-0' ? '0' : text;
  }

  function moves(expected) {
    return expected === null ? 'infinitely many' : expected.toFixed(1);
  }

  function number(cell, value, digits) {
    cell.className = 'number';
    cell.textContent = fixed(value, digits);
    cell.dataset.value = value === null ? 'inf' : String(value);
    return cell;
  }

  function start(d) {
    const grid = d.grid;
    const F = grid.cells.length;
    const cellAt = new Map();
    grid.cells.forEach((c, i) => cellAt.set(c[0] + ',' + c[1], i));
    const tupleIndex = new Map();
    d.tuples.forEach((t, i) => tupleIndex.set(t.join(','), i));
    const coveredTuple = new Map();
    d.slices.tuples.forEach((t, i) => coveredTuple.set(t, i));
    const coveredAdversary = new Map();
    d.slices.adversaries.forEach((a, i) => coveredAdversary.set(a, i));
    const tagOf = reader(d.slices.tags);
    const choiceOf = reader(d.slices.choices);
    const valueOf = reader(d.slices.values);
    const supportOf = reader(d.slices.adversary);
    const reactiveOf = new Map(d.slices.reactive.map((entry) => [entry[0], reader(entry[1])]));
    const tables = new Map(d.tables);
    const automata = d.automata;
    const forbidden = grid.collision === 'forbidden';
    const dark = new Set(d.dark);

    // The index of the state with the robot on r in slice (tuple, adversary), -1 if not covered.
    function index(tuple, adversary, r) {
      const t = coveredTuple.get(tuple);
      const a = coveredAdversary.get(adversary);
      if (t === undefined || a === undefined) return -1;
      return (t * d.slices.adversaries.length + a) * F + r;
    }

    function cellName(i) {
      return '(' + grid.cells[i][0] + ',' + grid.cells[i][1] + ')';
    }

    // Arena and product state names as the reports write them (docs/semantics.md §11).
    function arenaName(r, a, robotTurn) {
      return '(' + cellName(r) + ',' + cellName(a) + ',' + (robotTurn ? 0 : 1) + ')';
    }

    function productName(r, a, robotTurn, tuple) {
      return arenaName(r, a, robotTurn) + '|' + d.tuples[tuple].join('|');
    }

    function letter(r, a) {
      return r === a ? grid.shared[r] : grid.letters[r];
    }

    // Where move m (of `moves`) leads from cell `from`, the other player on `other`; -1 if nowhere.
    function target(from, other, m, list) {
      const move = list[m];
      const c = grid.cells[from];
      const to = cellAt.get((c[0] + move.dx) + ',' + (c[1] + move.dy));
      if (to === undefined || (forbidden && to === other)) return -1;
      return to;
    }

    // ---------------------------------------------------------------- the header and report
    $('title').textContent = d.title;
    $('lines').textContent = d.lines.join('\n');
    for (const note of d.notes) html('li', note, $('notes'));
    for (const [name, value] of d.summary) {
      html('dt', name, $('summary'));
      html('dd', value, $('summary'));
    }
    $('report').textContent = d.report;
    $('labels-name').textContent = d.key.heading.toLowerCase().startsWith('win-label')
      ? 'win-labels' : 'guarantees';

    // ---------------------------------------------------------------- the board
    const board = $('board');
    const side = Math.max(grid.width, grid.height);
    const size = Math.min(72, Math.max(14, Math.floor(640 / side)));
    const roomy = size >= 28;
    // A roomy cell has three zones, as the static pictures (render/picture.rs): a band at the
    // top for its propositions, a band at the bottom for its code or value, and the disc
    // between them for the controller's mark and the players, so that no text meets a mark.
    const codeSize = Math.min(12, Math.max(8, size * 0.17));
    const band = roomy ? Math.ceil(codeSize * 1.3) : 0;
    const disc = roomy ? size / 2 - band - 1.5 : size * 0.3;
    // markPath draws within 0.46 of its scale from the centre.
    const markScale = roomy ? disc / 0.46 : size;
    const left = 34;
    const top = 8;
    const width = left + grid.width * size + 12;
    const height = top + grid.height * size + 34;
    for (const [name, value] of [['width', width], ['height', height],
      ['viewBox', '0 0 ' + width + ' ' + height]]) board.setAttribute(name, value);
    // The map's column is as wide as the board (its controls wrap), so that the side column
    // has the rest of the window.
    $('board-column').style.flex = '0 0 ' + Math.max(width, 480) + 'px';
    function corner(i) {
      const c = grid.cells[i];
      return [left + c[0] * size, top + (grid.height - 1 - c[1]) * size];
    }
    function centre(i) {
      const p = corner(i);
      return [p[0] + size / 2, p[1] + size / 2];
    }
    element('rect', { x: 0, y: 0, width: width, height: height, fill: '#ffffff' }, board);
    const cellLayer = element('g', {}, board);
    const rects = [];
    const titles = [];
    const codes = [];
    const marks = [];
    const heads = [];
    for (let i = 0; i < F; i++) {
      const p = corner(i);
      const rect = element('rect', {
        x: p[0], y: p[1], width: size, height: size, fill: '#ffffff', class: 'cell',
        'data-cell': i, 'data-x': grid.cells[i][0], 'data-y': grid.cells[i][1],
      }, cellLayer);
      titles.push(element('title', {}, rect));
      rects.push(rect);
    }
    // Cells whose state cannot occur in the slice shown: hatched.
    const hatches = [];
    for (let i = 0; i < F; i++) {
      hatches.push(element('path', { d: hatching(corner(i), size), class: 'hatch',
        visibility: 'hidden' }, cellLayer));
    }
    // Obstacles.
    for (let x = 0; x < grid.width; x++) {
      for (let y = 0; y < grid.height; y++) {
        if (cellAt.has(x + ',' + y)) continue;
        const px = left + x * size;
        const py = top + (grid.height - 1 - y) * size;
        element('rect', { x: px, y: py, width: size, height: size, fill: '#4D4D4D' }, board);
        if (roomy) {
          const t = element('text', {
            x: px + size / 2, y: py + size / 2 + size * 0.14, 'text-anchor': 'middle',
            'font-size': size * 0.4, fill: '#ffffff', 'font-weight': 'bold',
          }, board);
          t.textContent = 'O';
        }
      }
    }
    const markLayer = element('g', {}, board);
    const strokeWidth = Math.max(markScale / 14, 1.5);
    for (let i = 0; i < F; i++) {
      marks.push(element('path', { class: 'mark', 'stroke-width': strokeWidth, d: '' }, markLayer));
      heads.push(element('path', { class: 'arrowhead', d: '' }, markLayer));
      if (roomy) {
        const p = corner(i);
        codes.push(element('text', {
          x: p[0] + size / 2, y: p[1] + size - 3, 'text-anchor': 'middle', class: 'code',
        }, markLayer));
      }
    }
    // Grid lines and coordinates.
    let lines = '';
    for (let x = 0; x <= grid.width; x++) {
      lines += 'M' + (left + x * size) + ' ' + top + 'V' + (top + grid.height * size);
    }
    for (let y = 0; y <= grid.height; y++) {
      lines += 'M' + left + ' ' + (top + y * size) + 'H' + (left + grid.width * size);
    }
    element('path', { d: lines, stroke: '#999999', 'stroke-width': 1, fill: 'none',
      'pointer-events': 'none' }, board);
    const step = roomy ? 1 : 5;
    for (let x = 0; x < grid.width; x += step) {
      element('text', { x: left + x * size + size / 2, y: top + grid.height * size + 14,
        'text-anchor': 'middle', class: 'coord' }, board).textContent = String(x);
    }
    for (let y = 0; y < grid.height; y += step) {
      element('text', { x: left - 6, y: top + (grid.height - 1 - y) * size + size / 2 + 4,
        'text-anchor': 'end', class: 'coord' }, board).textContent = String(y);
    }
    element('text', { x: left, y: top + grid.height * size + 28, class: 'coord' }, board)
      .textContent = 'x eastward, y northward';
    // Propositions at the top left of their cells.
    const propositions = new Map();
    for (const [name, i] of grid.labels) {
      if (!propositions.has(i)) propositions.set(i, []);
      propositions.get(i).push(name);
    }
    const propSize = roomy ? codeSize : Math.min(16, Math.max(9, size * 0.3));
    for (const [i, names] of propositions) {
      const p = corner(i);
      element('text', { x: p[0] + 3, y: p[1] + (roomy ? band - 3 : propSize + 1),
        'font-size': propSize, class: 'prop' }, board).textContent = names.join(',');
    }
    const overlay = element('g', { 'pointer-events': 'none' }, board);
    const robotPath = element('path', { class: 'path-robot', 'stroke-width': Math.max(size / 12, 2) }, overlay);
    const adversaryPath = element('path', { class: 'path-adversary', 'stroke-width': Math.max(size / 12, 2) }, overlay);
    const targets = element('g', {}, overlay);
    const selected = element('rect', { class: 'selected', width: size - 4, height: size - 4 }, overlay);
    selected.setAttribute('visibility', 'hidden');
    const radius = roomy ? Math.min(size * 0.28, disc) : size * 0.28;
    const robotShape = element('circle', { r: radius, fill: '#0072B2', stroke: '#000000',
      'stroke-width': 1.5 }, overlay);
    const adversaryShape = element('path', { fill: '#E69F00', stroke: '#000000',
      'stroke-width': 1.5 }, overlay);

    // Diagonal lines across the square of side s at p.
    function hatching(p, s) {
      let path = '';
      for (let c = 5; c < 2 * s; c += 6) {
        const a = Math.min(c, s);
        path += 'M' + (p[0] + a) + ' ' + (p[1] + c - a) + 'L' + (p[0] + c - a) + ' ' + (p[1] + a);
      }
      return path;
    }

    function diamond(c, r) {
      return 'M' + c[0] + ' ' + (c[1] - r) + 'L' + (c[0] + r) + ' ' + c[1] + 'L' + c[0] + ' ' +
        (c[1] + r) + 'L' + (c[0] - r) + ' ' + c[1] + 'Z';
    }

    function circle(c, r) {
      return 'M' + (c[0] - r) + ' ' + c[1] + 'a' + r + ' ' + r + ' 0 1 0 ' + (2 * r) + ' 0a' + r +
        ' ' + r + ' 0 1 0 ' + (-2 * r) + ' 0';
    }

    // The controller's mark centred on c in a cell of side s (as the static pictures draw it):
    // [the stroked path, the filled arrowhead].
    function markPath(choice, c, s) {
      if (!choice) return ['', ''];
      if (choice.move !== undefined) {
        const move = grid.robot_moves[choice.move];
        const length = Math.hypot(move.dx, move.dy);
        if (length === 0) return [circle(c, s * 0.3), ''];
        const dx = move.dx / length;
        const dy = -move.dy / length;
        const at = (k) => [c[0] + dx * s * k, c[1] + dy * s * k];
        const from = at(0.12);
        const base = at(0.28);
        const tip = at(0.46);
        const nx = -dy * s * 0.11;
        const ny = dx * s * 0.11;
        return ['M' + from[0] + ' ' + from[1] + 'L' + base[0] + ' ' + base[1],
          'M' + tip[0] + ' ' + tip[1] + 'L' + (base[0] + nx) + ' ' + (base[1] + ny) + 'L' +
          (base[0] - nx) + ' ' + (base[1] - ny) + 'Z'];
      }
      if (choice.stop !== undefined) {
        const r = s * 0.22;
        return ['M' + (c[0] - r) + ' ' + (c[1] - r) + 'h' + 2 * r + 'v' + 2 * r + 'h' + -2 * r + 'Z', ''];
      }
      if (choice.commit !== undefined) return [circle(c, s * 0.16) + circle(c, s * 0.26), ''];
      const a = s * 0.1;
      const b = s * 0.26;
      let path = '';
      for (const [sx, sy] of [[1, 1], [1, -1], [-1, 1], [-1, -1]]) {
        path += 'M' + (c[0] + sx * a) + ' ' + (c[1] + sy * a) + 'L' + (c[0] + sx * b) + ' ' + (c[1] + sy * b);
      }
      return [path, ''];
    }

    function choiceObject(c) {
      const choice = d.choices[c];
      return typeof choice === 'string' ? { give_up: true } : choice;
    }

    // The colour of t in [0, 1] on the value scale.
    function heat(t) {
      return d.heat[Math.max(0, Math.min(100, Math.round(t * 100)))];
    }

    // The range of the positive values of a slice's robot states and how many decimals tell
    // them apart (as the static value picture's scale: render/picture.rs `value_range`; the
    // page has values to the hundredth), or null when none is positive.
    function valueRange(tuple, adversary) {
      let lo = Infinity;
      let hi = -Infinity;
      for (let r = 0; r < F; r++) {
        const i = tuple === undefined ? -1 : index(tuple, adversary, r);
        if (i < 0 || tagOf(i) < 0) continue;
        const v = valueOf(i) / 100;
        if (v > 0) {
          lo = Math.min(lo, v);
          hi = Math.max(hi, v);
        }
      }
      if (lo > hi) return null;
      const spread = hi - lo;
      let decimals = 0;
      if (spread > 1e-9 * Math.max(1, Math.abs(hi))) {
        decimals = Math.max(0, Math.min(2, 1 - Math.floor(Math.log10(spread))));
      } else if (Math.abs(hi - Math.round(hi)) >= 1e-9) {
        decimals = 2;
      }
      return { lo, hi, decimals };
    }

    // The fill of a state worth `value` on the slice's scale `range`: the nothing colour at 0.
    function shade(value, range) {
      if (!(value > 0)) return d.nothing;
      if (!range || range.hi <= range.lo) return heat(0.5);
      return heat((value - range.lo) / (range.hi - range.lo));
    }

    // Per automaton and letter, the states the automaton can be in right after reading the
    // letter: a robot cell whose slice's state is not among them for some automaton cannot
    // occur there (entering the cell moves the automaton on: the robot would be past it).
    const afterReading = automata.map((a) => {
      const letters = a.table.step[0].length;
      const sets = [];
      for (let l = 0; l < letters; l++) sets.push(new Set(a.table.step.map((row) => row[l])));
      return sets;
    });
    function canOccur(tuple, r, adversary) {
      const l = letter(r, adversary);
      return d.tuples[tuple].every((q, k) => afterReading[k][l].has(q));
    }

    // ---------------------------------------------------------------- slices
    // What the board shows: the slice (automata tuple, adversary cell), the robot if placed,
    // the players' paths, the adversary's possible next cells.
    const view = { tuple: d.start.tuple, adversary: d.start.adversary, shading: 'labels',
      selected: -1 };

    function drawSlice(tuple, adversary, extra) {
      extra = extra || {};
      const values = view.shading === 'values' && valueOf;
      const range = values ? valueRange(tuple, adversary) : null;
      if (values) {
        view.range = range;
        drawLegend();
      }
      let covered = false;
      for (let r = 0; r < F; r++) {
        const i = tuple === undefined ? -1 : index(tuple, adversary, r);
        const tag = i < 0 ? -1 : tagOf(i);
        if (i >= 0) covered = true;
        let fill = '#ffffff';
        let code = '';
        let title = 'robot at ' + cellName(r);
        let mark = ['', ''];
        if (tag >= 0) {
          const t = d.tags[tag];
          const value = valueOf ? valueOf(i) / 100 : null;
          fill = values ? shade(value, range) : t.colour;
          code = values ? value.toFixed(value > 0 && range ? range.decimals : 0) : t.code;
          title += ': ' + t.text + (value === null ? '' : ', value ' + value.toFixed(2));
          if (choiceOf) {
            const c = choiceOf(i);
            if (c >= 0) mark = markPath(choiceObject(c), centre(r), markScale);
          }
        } else if (r === adversary && forbidden) {
          title += ': the adversary is there';
        } else if (i >= 0) {
          title += ': no such product state';
        } else {
          title += ': this slice is not in the page';
        }
        const impossible = tag >= 0 && !canOccur(tuple, r, adversary);
        if (impossible) {
          title += ' (cannot occur in a play: entering this cell moves the automata on, as after ' +
            'visiting it)';
        }
        hatches[r].setAttribute('visibility', impossible ? 'visible' : 'hidden');
        rects[r].setAttribute('fill', fill);
        const ink = dark.has(fill) ? '#ffffff' : '#000000';
        marks[r].style.stroke = ink;
        heads[r].style.fill = ink;
        titles[r].textContent = title;
        marks[r].setAttribute('d', mark[0]);
        heads[r].setAttribute('d', mark[1]);
        if (roomy) {
          codes[r].textContent = code;
          const fitting = (size - 6) / (0.62 * Math.max(1, code.length));
          codes[r].setAttribute('font-size', Math.min(codeSize, fitting));
        }
      }
      adversaryShape.setAttribute('d', diamond(centre(adversary), radius));
      if (extra.robot !== undefined) {
        const c = centre(extra.robot);
        robotShape.setAttribute('cx', c[0]);
        robotShape.setAttribute('cy', c[1]);
        robotShape.setAttribute('visibility', 'visible');
      } else {
        robotShape.setAttribute('visibility', 'hidden');
      }
      const polyline = (cellsOnPath, shift) => cellsOnPath.map((cell, k) => {
        const c = centre(cell);
        return (k ? 'L' : 'M') + (c[0] + shift) + ' ' + (c[1] + shift);
      }).join('');
      robotPath.setAttribute('d', polyline(extra.robotPath || [], -size * 0.12));
      adversaryPath.setAttribute('d', polyline(extra.adversaryPath || [], size * 0.12));
      targets.replaceChildren();
      for (const cell of extra.targets || []) {
        const p = corner(cell);
        element('rect', { x: p[0] + 3, y: p[1] + 3, width: size - 6, height: size - 6,
          class: 'target' }, targets);
      }
      const automataText = automata.map((a, k) => a.title + ' = ' +
        (tuple === undefined ? '?' : d.tuples[tuple][k])).join(', ');
      $('slice').textContent = 'Adversary at ' + cellName(adversary) + '; automata at ' +
        automataText + (tuple === d.start.tuple ? ' (as in h0)' : '') +
        (covered ? '' : ' (this slice is not in the page)');
      if (view.selected >= 0 && mode === 'explore') {
        const p = corner(view.selected);
        selected.setAttribute('x', p[0] + 2);
        selected.setAttribute('y', p[1] + 2);
        selected.setAttribute('visibility', 'visible');
      } else {
        selected.setAttribute('visibility', 'hidden');
      }
    }

    // ---------------------------------------------------------------- the legend
    function drawLegend() {
      const legend = $('legend');
      legend.replaceChildren();
      const swatch = (parent, draw) => {
        const s = document.createElementNS(SVG, 'svg');
        s.setAttribute('width', 22);
        s.setAttribute('height', 22);
        draw(s);
        parent.appendChild(s);
      };
      const list = (heading) => {
        html('h3', heading, legend);
        return html('ul', null, legend);
      };
      if (view.shading === 'values' && valueOf) {
        const ul = list('Value of the robot\'s state');
        const range = view.range;
        if (!range) {
          html('li', 'no positive value to show', ul);
        } else if (range.hi <= range.lo) {
          const li = html('li', null, ul);
          swatch(li, (s) => element('rect', { x: 2, y: 2, width: 18, height: 18,
            fill: heat(0.5), stroke: '#000000' }, s));
          html('span', 'uniform: every state shown is worth ' + range.lo.toFixed(range.decimals), li);
        } else {
          // The colour bar, from the slice's lowest positive value to its highest.
          const li = html('li', null, ul);
          li.className = 'scale';
          swatch(li, (s) => {
            s.setAttribute('height', 122);
            for (let k = 0; k <= 20; k++) {
              element('rect', { x: 2, y: 2 + (20 - k) * 5.9, width: 18, height: 6.4,
                fill: heat(k / 20) }, s);
            }
            element('rect', { x: 2, y: 2, width: 18, height: 118, fill: 'none',
              stroke: '#000000' }, s);
          });
          const ticks = html('span', null, li);
          ticks.className = 'ticks';
          html('span', range.hi.toFixed(range.decimals), ticks);
          html('span', ((range.lo + range.hi) / 2).toFixed(range.decimals), ticks);
          html('span', range.lo.toFixed(range.decimals), ticks);
        }
        const zero = html('li', null, ul);
        swatch(zero, (s) => element('rect', { x: 2, y: 2, width: 18, height: 18,
          fill: d.nothing, stroke: '#000000' }, s));
        html('span', '0: nothing can be gained', zero);
        html('li', 'the scale spans the positive values shown (payoffs go up to ' +
          fixed(d.max, 6) + ')', ul);
      } else {
        const ul = list(d.key.heading);
        for (const [colour, text] of d.key.entries) {
          const li = html('li', null, ul);
          swatch(li, (s) => {
            if (colour) element('rect', { x: 2, y: 2, width: 18, height: 18, fill: colour,
              stroke: '#000000' }, s);
          });
          html('span', text, li);
        }
      }
      if (choiceOf) {
        const ul = list('Controller in each robot cell');
        const east = grid.robot_moves.findIndex((m) => m.dx > 0 && m.dy === 0);
        for (const [choice, text] of [
          [{ move: east >= 0 ? east : 0 }, 'moves (arrow)'],
          [{ stop: 1 }, 'stops: settles for a sub-task'],
          [{ commit: 1 }, 'commits: plays to win a task'],
          [{ give_up: true }, 'gives up: stuck, nothing to gain']]) {
          const li = html('li', null, ul);
          swatch(li, (s) => {
            const paths = markPath(choice, [11, 11], 22);
            element('path', { d: paths[0], class: 'mark', fill: 'none', stroke: '#000000',
              'stroke-width': 1.6 }, s);
            element('path', { d: paths[1], fill: '#000000' }, s);
          });
          html('span', text, li);
        }
      }
      {
        const ul = list('Slice');
        const li = html('li', null, ul);
        swatch(li, (s) => {
          element('rect', { x: 2, y: 2, width: 18, height: 18, fill: '#9e9e9e',
            stroke: '#000000' }, s);
          element('path', { d: hatching([2, 2], 18), class: 'hatch' }, s);
        });
        html('span', 'hatched: cannot occur in a play with these automata states, since ' +
          'entering the cell moves them on (on a goal cell, the robot would be past the goal: ' +
          'see "visit")', li);
      }
      const ul = list('Players');
      for (const [shape, text] of [['robot', 'the robot'], ['adversary', 'the adversary']]) {
        const li = html('li', null, ul);
        swatch(li, (s) => {
          if (shape === 'robot') {
            element('circle', { cx: 11, cy: 11, r: 8, fill: '#0072B2', stroke: '#000000' }, s);
          } else {
            element('path', { d: diamond([11, 11], 8), fill: '#E69F00', stroke: '#000000' }, s);
          }
        });
        html('span', text, li);
      }
    }

    // ---------------------------------------------------------------- explore
    let mode = 'explore';
    const explore = { q: d.tuples[d.start.tuple].slice() };

    function exploreTuple() {
      return tupleIndex.get(explore.q.join(','));
    }

    function showExplore() {
      drawSlice(exploreTuple(), view.adversary);
      automata.forEach((a, k) => { selects[k].value = String(explore.q[k]); });
    }

    const selects = automata.map((a, k) => {
      const label = html('label', a.title + ' ', $('automata-selects'));
      const select = html('select', null, label);
      for (const q of a.states) html('option', String(q), select).value = String(q);
      select.addEventListener('change', () => {
        explore.q[k] = Number(select.value);
        showExplore();
      });
      return select;
    });
    // "as after visiting P": each automaton reads the letter of P's cell once.
    const visited = new Set();
    for (const [name, cell] of grid.labels) {
      if (visited.has(name)) continue;
      visited.add(name);
      const button = html('button', 'visit ' + name, $('visits'));
      button.type = 'button';
      button.title = 'the automata as after the robot enters ' + name + '\'s cell ' + cellName(cell);
      button.addEventListener('click', () => {
        const l = grid.letters[cell];
        explore.q = explore.q.map((q, k) => automata[k].table.step[q][l]);
        showExplore();
      });
    }
    $('reset-slice').addEventListener('click', () => {
      explore.q = d.tuples[d.start.tuple].slice();
      view.adversary = d.start.adversary;
      showExplore();
    });
    if (d.slices.tuples.length < d.tuples.length) {
      $('automata').disabled = true;
    }
    if (d.slices.adversaries.length < F) {
      $('click-place').disabled = true;
    }
    for (const input of document.getElementsByName('shading')) {
      input.addEventListener('change', () => {
        view.shading = input.value;
        if (!valueOf) view.shading = 'labels';
        drawLegend();
        redraw();
      });
    }
    if (!valueOf) $('shade-values').disabled = true;

    function showDecision(r) {
      const box = $('decision');
      box.replaceChildren();
      const tuple = exploreTuple();
      const i = tuple === undefined ? -1 : index(tuple, view.adversary, r);
      const table = tables.get(i);
      if (!table) {
        const name = tuple === undefined ? null : productName(r, view.adversary, true, tuple);
        if (r === view.adversary && forbidden) {
          html('p', 'The adversary is on ' + cellName(r) + '.', box);
        } else if (i < 0) {
          html('p', 'This slice is not in the page.', box);
        } else if (tagOf(i) < 0) {
          html('p', 'The product has no state ' + name + '.', box);
        } else if (!choiceOf) {
          html('p', 'State ' + name + ': ' + d.tags[tagOf(i)].text + '.', box);
        } else {
          const p = html('p', 'The decision table of ' + name + ' is not in the page: ask the command line with --explain=' + name + '.', box);
          p.dataset.state = name;
        }
        return;
      }
      const head = html('p', null, box, 'state');
      head.append('Decision table of ');
      html('code', table.state, head, 'name');
      head.append('  ');
      html('span', table.label, head, 'label');
      head.append(': value ');
      number(html('span', null, head), table.value, 6);
      head.append(', expected ');
      const expected = html('span', moves(table.expected_moves), head, 'moves');
      expected.dataset.value = table.expected_moves === null ? 'inf' : String(table.expected_moves);
      head.append(' robot moves');
      if (table.actions.length === 0) {
        html('p', 'No decision: the state is absorbing or an adversary state.', box);
      } else {
        const t = html('table', null, box, 'decision');
        const header = html('tr', null, html('thead', null, t));
        for (const h of ['action', 'value', 'expected moves', 'next robot state', 'label', 'p', 'value']) {
          html('th', h, header);
        }
        const body = html('tbody', null, t);
        for (const row of table.actions) {
          const tr = html('tr', null, body, row.action === table.chosen ? 'action chosen' : 'action');
          html('td', row.action, tr, 'action-name');
          number(html('td', null, tr), row.value, 6);
          const m = html('td', moves(row.expected_moves), tr, 'number');
          m.dataset.value = row.expected_moves === null ? 'inf' : String(row.expected_moves);
          html('td', null, tr).colSpan = 4;
          for (const o of row.outcomes) {
            const otr = html('tr', null, body, 'outcome');
            html('td', null, otr).colSpan = 3;
            html('td', o.state, otr, 'outcome-state');
            html('td', o.label, otr, 'outcome-label');
            number(html('td', null, otr), o.probability, 6);
            number(html('td', null, otr), o.value, 6);
          }
        }
      }
      const chosen = html('p', 'chosen: ', box);
      html('span', table.chosen === null ? '-' : table.chosen, chosen, 'chosen-action');
    }

    board.addEventListener('click', (event) => {
      const cell = event.target.dataset ? event.target.dataset.cell : undefined;
      if (cell === undefined) return;
      const r = Number(cell);
      if (mode === 'explore') {
        if ($('click-place').checked) {
          if (coveredAdversary.has(r)) {
            view.adversary = r;
            if (view.selected === r) view.selected = -1;
            drawSlice(exploreTuple(), view.adversary);
            if (view.selected >= 0) showDecision(view.selected);
          }
        } else {
          view.selected = r;
          drawSlice(exploreTuple(), view.adversary);
          showDecision(r);
        }
      } else if (mode === 'play') {
        playAdversary(r);
      }
      document.body.dataset.lastUpdateMs = String(performance.now() - event.timeStamp);
    });

    // ---------------------------------------------------------------- the run
    const run = d.run;
    let runAt = 0;
    const runRows = [];
    if (run) {
      $('run-summary').textContent = 'Seed ' + run.seed + ', ' + run.steps.length +
        ' steps: outcome ' + run.outcome + ', payoff ' + fixed(run.payoff, 6) + '.';
      const body = $('run-table').tBodies[0];
      run.steps.forEach((s, k) => {
        const tr = html('tr', null, body);
        html('td', String(k), tr, 'number');
        html('td', s.state, tr, 'run-state');
        html('td', s.label, tr, 'run-label');
        html('td', s.action === null ? '-' : s.action, tr, 'run-action');
        html('td', s.committed === null ? '' : s.committed, tr, 'run-committed');
        tr.addEventListener('click', () => showRun(k));
        runRows.push(tr);
      });
      $('run-slider').max = String(run.steps.length - 1);
    } else {
      $('tab-run').disabled = true;
    }

    function path(cellsAlong) {
      const out = [];
      for (const c of cellsAlong) if (out.length === 0 || out[out.length - 1] !== c) out.push(c);
      return out;
    }

    function showRun(k) {
      runAt = Math.max(0, Math.min(run.steps.length - 1, k));
      const s = run.steps[runAt];
      const upTo = run.steps.slice(0, runAt + 1);
      drawSlice(s.tuple, s.adversary, {
        robot: s.robot,
        robotPath: path(upTo.map((x) => x.robot)),
        adversaryPath: path(upTo.map((x) => x.adversary)),
      });
      runRows.forEach((tr, j) => { tr.className = j === runAt ? 'current' : ''; });
      $('run-slider').value = String(runAt);
      $('run-position').textContent = 'step ' + runAt + ' of ' + (run.steps.length - 1) + ': ' +
        s.state + (s.action === null ? '' : ', ' + (s.robot_turn ? 'robot' : 'adversary') + ' plays ' + s.action);
      $('run-position').dataset.step = String(runAt);
      runRows[runAt].scrollIntoView({ block: 'nearest' });
    }
    $('run-first').addEventListener('click', () => showRun(0));
    $('run-back').addEventListener('click', () => showRun(runAt - 1));
    $('run-forward').addEventListener('click', () => showRun(runAt + 1));
    $('run-last').addEventListener('click', () => showRun(run.steps.length - 1));
    $('run-slider').addEventListener('input', () => showRun(Number($('run-slider').value)));

    // ---------------------------------------------------------------- playing the adversary
    // A port of the executor (crates/hypersynth/src/opportunistic/executor.rs) over the page's
    // tables: it tracks the automata from the states' labels, flags the adversary's moves the
    // model gives probability 0, and answers each robot turn.
    const canPlay = Boolean(supportOf && choiceOf);
    if (!canPlay) $('tab-play').disabled = true;
    let P = null;
    let clicks = [];

    function holds(set) {
      return automata.every((a, k) => !(set & (1 << k)) || a.table.finals.includes(P.q[k]));
    }

    function answerLine(answer) {
      const name = (m) => grid.robot_moves[m].name;
      if (answer.move !== undefined) return name(answer.move);
      if (answer.set !== undefined) {
        return (answer.stop ? 'stop ' : 'commit ') + d.sets[answer.set] + ' ' +
          (answer.then === null ? 'done' : name(answer.then));
      }
      return answer.done ? 'done' : 'give up';
    }

    // The controller's answer at the robot state just observed (throws where it has none).
    function respond(stepNumber) {
      if (P.gaveUp) return { giveUp: true };
      const tuple = tupleIndex.get(P.q.join(','));
      const i = tuple === undefined ? -1 : index(tuple, P.a, P.r);
      const notCovered = () => new Error('step ' + stepNumber + ': the controller has no choice at `' +
        arenaName(P.r, P.a, true) + '` (automata at [' + P.q.join(', ') + ']): the play left the states it was exported for');
      const reactive = (set) => {
        const table = reactiveOf.get(set);
        const m = table && i >= 0 ? table(i) : -1;
        if (m < 0) throw notCovered();
        return m;
      };
      if (P.committed !== null) {
        if (holds(P.committed)) return { done: true };
        return { move: reactive(P.committed) };
      }
      const c = i >= 0 ? choiceOf(i) : -1;
      if (c < 0) throw notCovered();
      const choice = choiceObject(c);
      if (choice.move !== undefined) return { move: choice.move };
      if (choice.give_up) {
        P.gaveUp = true;
        return { giveUp: true };
      }
      const set = choice.stop !== undefined ? choice.stop : choice.commit;
      P.committed = set;
      return { set: set, stop: choice.stop !== undefined, then: holds(set) ? null : reactive(set) };
    }

    // The next state of the play: the robot on r, the adversary on a; `move` is what led there
    // ({ robot: bool, index }), null for the first state.
    function observe(r, a, robotTurn, move) {
      const stepNumber = P.step;
      let warning = null;
      if (move === null) {
        P.q = automata.map((x) => x.table.step[x.table.initial][letter(r, a)]);
      } else {
        if (!move.robot) {
          const tuple = tupleIndex.get(P.q.join(','));
          const i = tuple === undefined ? -1 : index(tuple, P.a, P.r);
          const entry = i >= 0 ? supportOf(i) : -1;
          if (entry >= 0 && Math.floor(entry / Math.pow(2, move.index + 1)) % 2 === 0) {
            warning = 'step ' + stepNumber + ': off-model move: the adversary played `' +
              grid.adversary_moves[move.index].name + '`, which the model gives probability 0; play goes on';
          }
        } else if (P.answered !== null && P.answered !== move.index) {
          warning = 'step ' + stepNumber + ': the robot did not play `' +
            grid.robot_moves[P.answered].name + '` as answered; play goes on';
        }
        P.q = P.q.map((q, k) => automata[k].table.step[q][letter(r, a)]);
      }
      P.r = r;
      P.a = a;
      P.robotTurn = robotTurn;
      P.step += 1;
      P.answered = null;
      P.robotPath.push(r);
      P.adversaryPath.push(a);
      const row = { step: stepNumber, state: arenaName(r, a, robotTurn), answer: null, warning: warning };
      P.rows.push(row);
      if (!robotTurn) return;
      try {
        const answer = respond(stepNumber);
        row.answer = answerLine(answer);
        if (answer.move !== undefined) P.answered = answer.move;
        else if (answer.then !== undefined && answer.then !== null) P.answered = answer.then;
        else P.over = answer.done ? 'Every sub-task of the set committed to holds: done.' : 'The controller gives up: nothing can be gained.';
      } catch (error) {
        row.answer = 'error';
        row.warning = error.message;
        P.over = 'The play cannot go on.';
      }
    }

    function adversaryTargets() {
      const out = [];
      grid.adversary_moves.forEach((m, k) => {
        const to = target(P.a, P.r, k, grid.adversary_moves);
        if (to >= 0 && !out.some((x) => x.cell === to)) out.push({ cell: to, index: k });
      });
      return out;
    }

    // After an answer, the robot plays it; then it is the adversary's turn.
    function settle() {
      while (!P.over && P.robotTurn) {
        const m = P.answered;
        const to = target(P.r, P.a, m, grid.robot_moves);
        observe(to, P.a, false, { robot: true, index: m });
      }
      if (!P.over && adversaryTargets().length === 0) P.over = 'The adversary is stuck: it has no move.';
    }

    function playReset(adversaryCells) {
      P = { step: 0, r: -1, a: -1, robotTurn: d.start.robot_first, q: null, committed: null,
        gaveUp: false, answered: null, over: null, rows: [], robotPath: [], adversaryPath: [] };
      observe(d.start.robot, d.start.adversary, d.start.robot_first, null);
      settle();
      clicks = [];
      for (const cell of adversaryCells) {
        if (P.over) break;
        const move = adversaryTargets().find((x) => x.cell === cell);
        if (!move) break;
        clicks.push(cell);
        observe(P.r, cell, true, { robot: false, index: move.index });
        settle();
      }
      showPlay();
    }

    function playAdversary(cell) {
      if (P.over) return;
      if (!adversaryTargets().some((x) => x.cell === cell)) return;
      playReset(clicks.concat([cell]));
    }

    function showPlay() {
      const tuple = tupleIndex.get(P.q.join(','));
      drawSlice(tuple, P.a, {
        robot: P.r,
        robotPath: path(P.robotPath),
        adversaryPath: path(P.adversaryPath),
        targets: P.over ? [] : adversaryTargets().map((x) => x.cell),
      });
      const body = $('play-table').tBodies[0];
      body.replaceChildren();
      for (const row of P.rows) {
        const tr = html('tr', null, body, row.warning ? 'warning' : '');
        html('td', String(row.step), tr, 'number');
        html('td', row.state, tr, 'play-state');
        const answer = html('td', row.answer === null ? '' : row.answer, tr, 'play-answer');
        if (row.warning) {
          answer.append(row.answer === null ? '' : ' ');
          html('span', row.warning, answer, 'play-warning');
        }
      }
      const committed = P.committed === null ? '' : '; committed to ' + d.sets[P.committed];
      $('play-prompt').textContent = P.over
        ? P.over
        : 'Your move: click one of the outlined cells' + committed + '.';
      $('play-prompt').dataset.over = P.over ? 'true' : 'false';
      body.lastElementChild && body.lastElementChild.scrollIntoView({ block: 'nearest' });
    }
    $('play-restart').addEventListener('click', () => playReset([]));
    $('play-undo').addEventListener('click', () => playReset(clicks.slice(0, -1)));

    // ---------------------------------------------------------------- modes
    function redraw() {
      if (mode === 'explore') showExplore();
      else if (mode === 'run') showRun(runAt);
      else showPlay();
    }

    function setMode(next) {
      mode = next;
      for (const name of ['explore', 'run', 'play']) {
        $('tab-' + name).setAttribute('aria-selected', String(name === mode));
        $('controls-' + name).hidden = name !== mode;
        $('panel-' + name).hidden = name !== mode;
      }
      if (mode === 'play' && P === null) playReset([]);
      redraw();
    }
    $('tab-explore').addEventListener('click', () => setMode('explore'));
    $('tab-run').addEventListener('click', () => setMode('run'));
    $('tab-play').addEventListener('click', () => setMode('play'));

    drawLegend();
    setMode('explore');
    status.textContent = '';
    document.body.dataset.ready = 'true';
  }

  load().then(start).catch((error) => fail('Cannot show the page: ' + error.message));
})();
