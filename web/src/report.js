/* servotwin report glue: hands the charts of the embedded JSON document (#report-data) to uPlot,
   which draws them. It also records what happened, for people and for the headless-browser test,
   in attributes of the root element (data-report-status = loading, ok or failed; data-errors,
   data-charts, data-charts-drawn, data-charts-empty = counts) and every error in #report-errors. */
(function () {
  'use strict';

  var root = document.documentElement;
  var errors = [];

  function record(message) {
    errors.push(String(message));
    root.setAttribute('data-errors', String(errors.length));
    var box = document.getElementById('report-errors');
    if (box) {
      box.hidden = false;
      box.textContent = 'Errors while drawing this report:\n' + errors.join('\n');
    }
  }

  root.setAttribute('data-report-status', 'loading');
  root.setAttribute('data-errors', '0');
  window.addEventListener('error', function (e) {
    record('error: ' + (e.message || String(e.error || 'unknown')) + (e.lineno ? ' (line ' + e.lineno + ')' : ''));
  });
  window.addEventListener('unhandledrejection', function (e) {
    record('unhandled rejection: ' + String(e.reason));
  });
  ['error', 'warn'].forEach(function (level) {
    var original = console[level];
    console[level] = function () {
      record('console.' + level + ': ' + Array.prototype.map.call(arguments, String).join(' '));
      return original.apply(console, arguments);
    };
  });

  // Saturated colours only: the drawing check below tells curves from the grey grid and axes.
  var PALETTE = ['#1f77b4', '#d62728', '#2ca02c', '#ff7f0e', '#9467bd', '#17becf', '#e377c2', '#8c6d1f', '#bcbd22'];
  var HEIGHT = 320;

  function color(i) {
    return PALETTE[i % PALETTE.length];
  }

  function formatValue(v) {
    if (v == null || !isFinite(v)) return '\u2014';
    if (v === 0) return '0';
    var a = Math.abs(v);
    return a >= 1e-3 && a < 1e6 ? String(Number(v.toPrecision(6))) : v.toExponential(4);
  }

  // Axis width from its longest tick label, so that small or long numbers are never cut.
  function axisSize(u, values, axisIdx, cycleNum) {
    var axis = u.axes[axisIdx];
    if (cycleNum > 1) return axis._size;
    var size = axis.ticks.size + axis.gap;
    var longest = (values || []).reduce(function (a, v) { return v != null && String(v).length > a.length ? String(v) : a; }, '');
    if (longest !== '') {
      u.ctx.font = axis.font[0];
      size += u.ctx.measureText(longest).width / uPlot.pxRatio;
    }
    return Math.ceil(size) + 2;
  }

  function axes(spec) {
    return [
      { label: spec.x_label, labelSize: 24 },
      { label: spec.y_label, size: axisSize, labelSize: 24 },
    ];
  }

  // Line charts: series sorted by x, aligned on the union of their x values (uPlot.join) so the
  // cursor shows every series at once; values missing after alignment are bridged, nulls in the
  // data (non-finite values) are gaps.
  function lineChart(spec, width) {
    var tables = spec.series.map(function (s) { return [s.x, s.y]; });
    var data = tables.length > 0 ? uPlot.join(tables) : [[]];
    var series = [{ label: spec.x_label || 'x', value: function (u, v) { return formatValue(v); } }];
    spec.series.forEach(function (s, i) {
      series.push({
        label: s.label,
        stroke: color(i),
        width: 1.5,
        spanGaps: false,
        value: function (u, v) { return formatValue(v); },
      });
    });
    return {
      opts: {
        width: width,
        height: HEIGHT,
        scales: {
          x: { time: false, distr: spec.x_log ? 3 : 1, log: 10 },
          y: { distr: spec.y_log ? 3 : 1, log: 10 },
        },
        axes: axes(spec),
        series: series,
        cursor: { drag: { x: true, y: false } },
        legend: { live: true },
      },
      data: data,
    };
  }

  // Path charts (uPlot's faceted mode 2): each series drawn in sample order, split into parts at
  // nulls (gaps); both axes span the same length per pixel.
  function pathChart(spec, width) {
    var parts = [];
    spec.series.forEach(function (s, i) {
      var xs = [], ys = [], first = true;
      function flush() {
        if (xs.length > 0) parts.push({ label: s.label, color: color(i), xs: xs, ys: ys, first: first });
        if (xs.length > 0) first = false;
        xs = [];
        ys = [];
      }
      for (var k = 0; k < s.x.length; k++) {
        if (s.x[k] === null || s.y[k] === null) flush();
        else {
          xs.push(s.x[k]);
          ys.push(s.y[k]);
        }
      }
      flush();
    });
    var bounds = { x0: Infinity, x1: -Infinity, y0: Infinity, y1: -Infinity };
    parts.forEach(function (p) {
      p.xs.forEach(function (v) { bounds.x0 = Math.min(bounds.x0, v); bounds.x1 = Math.max(bounds.x1, v); });
      p.ys.forEach(function (v) { bounds.y0 = Math.min(bounds.y0, v); bounds.y1 = Math.max(bounds.y1, v); });
    });
    if (!(bounds.x1 >= bounds.x0)) bounds = { x0: -1, x1: 1, y0: -1, y1: 1 };
    // uPlot's path builder decimates by pixel column from 4 points per column on, which assumes
    // sorted x: keep every part below that.
    var longest = parts.reduce(function (a, p) { return Math.max(a, p.xs.length); }, 0);
    var minPlot = Math.ceil(longest / 4) + 8;
    var size = Math.max(Math.min(width, 760), minPlot + 110);

    // Equal length per pixel: widen the narrower extent to the plot area's aspect ratio.
    function equalRange(u, key) {
      var w = u.bbox.width || 1, h = u.bbox.height || 1;
      var cx = (bounds.x0 + bounds.x1) / 2, cy = (bounds.y0 + bounds.y1) / 2;
      var perPixel = Math.max((bounds.x1 - bounds.x0) / w, (bounds.y1 - bounds.y0) / h);
      if (!(perPixel > 0)) perPixel = (Math.max(Math.abs(cx), Math.abs(cy)) || 1) / Math.max(w, h);
      perPixel *= 1.06;
      return key === 'x' ? [cx - perPixel * w / 2, cx + perPixel * w / 2] : [cy - perPixel * h / 2, cy + perPixel * h / 2];
    }

    var series = [{}];
    parts.forEach(function (p) {
      series.push({
        label: p.label,
        class: p.first ? 'st-first' : 'st-continued',
        stroke: p.color,
        width: 1.5,
        paths: uPlot.paths.linear(),
        points: { show: false },
        facets: [{ scale: 'x', auto: true }, { scale: 'y', auto: true }],
        values: function (u, sidx, idx) {
          var d = u.data && u.data[sidx];
          if (idx == null || !d) return { x: '\u2014', y: '\u2014' };
          return { x: formatValue(d[0][idx]), y: formatValue(d[1][idx]) };
        },
      });
    });

    // Hover: the point of each part nearest to the cursor (in pixels).
    function nearest(u, seriesIdx) {
      if (seriesIdx === 0) return null;
      var left = u.cursor.left, top = u.cursor.top;
      if (left == null || left < 0) return null;
      var d = u.data[seriesIdx], best = null, bestDist = Infinity;
      for (var k = 0; k < d[0].length; k++) {
        var dx = u.valToPos(d[0][k], 'x') - left, dy = u.valToPos(d[1][k], 'y') - top;
        var dist = dx * dx + dy * dy;
        if (dist < bestDist) {
          bestDist = dist;
          best = k;
        }
      }
      return best;
    }

    return {
      opts: {
        mode: 2,
        width: size,
        height: size,
        scales: {
          x: { time: false, auto: true, range: function (u) { return equalRange(u, 'x'); } },
          y: { auto: true, range: function (u) { return equalRange(u, 'y'); } },
        },
        axes: axes(spec),
        series: series,
        cursor: { drag: { x: true, y: true, uni: 30 }, dataIdx: nearest },
        legend: { live: true },
      },
      data: [null].concat(parts.map(function (p) { return [p.xs, p.ys]; })),
    };
  }

  // A chart has drawn when its canvas holds coloured (curve) pixels; grid and axes are grey.
  function hasCurvePixels(u) {
    var canvas = u.ctx.canvas;
    if (canvas.width === 0 || canvas.height === 0) return false;
    var pixels = u.ctx.getImageData(0, 0, canvas.width, canvas.height).data;
    var count = 0;
    for (var i = 0; i < pixels.length; i += 4) {
      if (pixels[i + 3] < 64) continue;
      var r = pixels[i], g = pixels[i + 1], b = pixels[i + 2];
      if (Math.max(r, g, b) - Math.min(r, g, b) >= 40 && ++count >= 20) return true;
    }
    return false;
  }

  function hasDrawableData(spec) {
    return spec.series.some(function (s) {
      var finite = 0;
      for (var k = 0; k < s.y.length && finite < 2; k++) if (s.y[k] !== null && s.x[k] !== null) finite++;
      return finite >= (spec.path ? 2 : 1);
    });
  }

  function plotWidth(figure) {
    return Math.max(320, Math.floor(figure.clientWidth || 900) - 4);
  }

  function build() {
    var charts = [];
    var figures = document.querySelectorAll('figure.chart');
    var doc;
    try {
      doc = JSON.parse(document.getElementById('report-data').textContent);
    } catch (e) {
      record('the report data cannot be read: ' + e);
      root.setAttribute('data-report-status', 'failed');
      return;
    }
    root.setAttribute('data-charts', String(doc.charts.length));
    if (figures.length !== doc.charts.length)
      record('the page has ' + figures.length + ' chart figures but the data ' + doc.charts.length + ' charts');
    doc.charts.forEach(function (spec, i) {
      var figure = figures[i];
      if (!figure) return;
      var host = figure.querySelector('.plot');
      try {
        if (!hasDrawableData(spec)) {
          host.textContent = 'No finite values to draw.';
          host.className += ' empty';
          charts.push({ spec: spec, figure: figure, plot: null, empty: true });
          return;
        }
        var made = spec.path ? pathChart(spec, plotWidth(figure)) : lineChart(spec, plotWidth(figure));
        charts.push({ spec: spec, figure: figure, plot: new uPlot(made.opts, made.data, host), empty: false });
      } catch (e) {
        record('chart ' + (i + 1) + ' (' + spec.title + '): ' + (e && e.stack ? e.stack : e));
      }
    });

    // For people inspecting a report in the browser's console, and for the interaction test.
    window.servotwinReport = { charts: charts.map(function (c) { return c.plot; }), errors: errors };

    window.addEventListener('resize', function () {
      charts.forEach(function (c) {
        if (c.plot && !c.spec.path) c.plot.setSize({ width: plotWidth(c.figure), height: HEIGHT });
      });
    });

    // uPlot draws in a microtask after construction: check once everything has settled.
    setTimeout(function () {
      var drawn = 0, empty = 0;
      charts.forEach(function (c, i) {
        if (c.empty) {
          empty++;
          return;
        }
        try {
          if (hasCurvePixels(c.plot)) {
            drawn++;
            c.figure.setAttribute('data-drawn', 'true');
          } else {
            c.figure.setAttribute('data-drawn', 'false');
            record('chart ' + (i + 1) + ' (' + c.spec.title + ') drew no curve');
          }
        } catch (e) {
          record('chart ' + (i + 1) + ': cannot inspect the drawing: ' + e);
        }
      });
      root.setAttribute('data-charts-drawn', String(drawn));
      root.setAttribute('data-charts-empty', String(empty));
      root.setAttribute('data-report-status', errors.length === 0 ? 'ok' : 'failed');
    }, 0);
  }

  document.addEventListener('DOMContentLoaded', function () {
    try {
      build();
    } catch (e) {
      record('drawing failed: ' + (e && e.stack ? e.stack : e));
      root.setAttribute('data-report-status', 'failed');
    }
  });
})();
