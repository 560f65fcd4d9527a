% Reference values for core/hinf (H-infinity synthesis) and tuning/hinf (the mixed-sensitivity
% design of catalog C7.14), from GNU Octave's control package: hinfsyn with the SUBOPTIMAL method
% at a fixed gamma (SLICOT SB10FD, the central controller) for the controller's frequency response,
% and a bisection on gamma with the same SUBOPTIMAL call as the feasibility test for the optimal
% gamma. (The OPTIMAL method, SLICOT SB10AD, is only the starting bracket: with a tight TOLGAM it
% returned gamma = 9.09 for velocity_r4_friction, whose optimum is 1.298.)
% Run from the repository root:
%   octave --no-gui --quiet tools/reference/hinf_reference.m
% Writes tests/data/core/hinf_reference.json.
pkg load control
s = tf('s');

cases = {};

% The generalized plant [z1; z2; e] = [W1 (Pe u + V w); W2 u; -(Pe u + V w)] from one shared
% realization of [V Pe] (n states: the open-loop poles) and W2. Assembled by blocks: a minreal of
% the stacked system kept duplicate integrators.
function P = assemble(V, Pe, W2, Ms, n)
  G = minreal(ss([V Pe]));
  assert(rows(G.a) == n);
  [ag, bg, cg, dg] = ssdata(G);
  [aw, bw, cw, dw] = ssdata(ss(W2));
  nw = rows(aw);
  P = ss(blkdiag(ag, aw), [bg; zeros(nw, 1), bw], ...
         [cg/Ms, zeros(1, nw); zeros(1, n), cw; -cg, zeros(1, nw)], [dg/Ms; 0, dw; -dg]);
end

% C7.14 velocity mixed sensitivity on a normalized two-mass plant: Pe = Pm/s,
% z = [W1 y; W2 u], y_meas = -(Pe u + V w); the weights as printed (catalog C7.14), V's
% denominator = Pe's (the open-loop poles), built here from transfer functions, independently of
% the C++ realization.
function P = velocity_plant(r, zz, zp, a, w0S, w0T, xv, Ms, Mt)
  s = tf('s');
  N = s^2 + 2*zz*s + 1;
  D = s^2 + 2*zp*r*s + r^2;
  den = s*(s + a)*D;
  Pe = N/den;
  V = (s + w0S)^2*(s^2 + 2*xv*r*s + r^2)/den;
  W2 = (1/Mt)*(s + w0T)^2*(s + r)^2/((s + w0S)^2*(s^2 + 2*xv*r*s + r^2)*(w0T*r)^2);
  P = assemble(V, Pe, W2, Ms, 4);
end

% C7.14's position weights: Pe = Pm/s^2, cubes of (s + w0S) and (s + w0T) (catalog C7.14).
function P = position_plant(r, zz, zp, a, w0S, w0T, xv, Ms, Mt)
  s = tf('s');
  N = s^2 + 2*zz*s + 1;
  D = s^2 + 2*zp*r*s + r^2;
  den = s^2*(s + a)*D;
  Pe = N/den;
  V = (s + w0S)^3*(s^2 + 2*xv*r*s + r^2)/den;
  W2 = (1/Mt)*(s + w0T)^3*(s + r)^2/((s + w0S)^3*(s^2 + 2*xv*r*s + r^2)*(w0T^3*r^2));
  P = assemble(V, Pe, W2, Ms, 5);
end

% Catalog C7.16 (Sec. 7.4, eq. 7.165): two modes, the second with unit DC gain
% (w2^2/wz2^2)(s^2 + 2 zz2 wz2 s + wz2^2)/(s^2 + 2 z2 w2 s + w2^2). Passive: V as for one mode (so
% the controller may cancel mode 2); active: V with mode 2 relocated to damping xv (eq. 7.164).
function P = two_mode_plant(active, r, zz, zp, wz2, zz2, w2, z2, w0S, w0T, xv, Ms, Mt)
  s = tf('s');
  N = (s^2 + 2*zz*s + 1)*(w2^2/wz2^2)*(s^2 + 2*zz2*wz2*s + wz2^2);
  D1 = s^2 + 2*zp*r*s + r^2;
  D2 = s^2 + 2*z2*w2*s + w2^2;
  den = s^2*D1*D2;
  Pe = N/den;
  if active
    V = (s + w0S)^2*(s^2 + 2*xv*r*s + r^2)*(s^2 + 2*xv*w2*s + w2^2)/den;
  else
    V = (s + w0S)^2*(s^2 + 2*xv*r*s + r^2)/(s^2*D1);
  end
  W2 = (1/Mt)*(s + w0T)^2*(s + r)^2/((s + w0S)^2*(s^2 + 2*xv*r*s + r^2)*(w0T*r)^2);
  P = assemble(V, Pe, W2, Ms, 6);
end

% Catalog C7.17: load-side feedback, Pel = (1/s^2)(2 zz s + 1)/(s^2 + 2 zz r^2 s + r^2) (the
% frictionless two-mass load velocity with the integral action), V as for the motor, and
% W2 = (1/Mt)(s + w0T)^4/[(s + w0S)^2 (s^2 + 2 xv r s + r^2)(w0T r)^2].
function P = load_side_plant(r, zz, w0S, w0T, xv, Ms, Mt)
  s = tf('s');
  D = s^2 + 2*zz*r^2*s + r^2;
  den = s^2*D;
  Pe = (2*zz*s + 1)/den;
  V = (s + w0S)^2*(s^2 + 2*xv*r*s + r^2)/den;
  W2 = (1/Mt)*(s + w0T)^4/((s + w0S)^2*(s^2 + 2*xv*r*s + r^2)*(w0T*r)^2);
  P = assemble(V, Pe, W2, Ms, 4);
end

ls = struct('name', 'load_side_r3', 'r', 3, 'zz', 0.01, 'zp', 0.03, 'a', 0, 'w0S', 2, 'w0T', 6, 'xv', 0.8, 'Ms', 1.8, 'Mt', 1.8);
cases{end+1} = struct('name', ls.name, 'P', load_side_plant(ls.r, ls.zz, ls.w0S, ls.w0T, ls.xv, ls.Ms, ls.Mt), ...
                      'nmeas', 1, 'ncon', 1, 'weights', ls);

modes = {struct('name', 'two_modes_passive', 'active', 0), struct('name', 'two_modes_active', 'active', 1)};
for i = 1:numel(modes)
  m = modes{i};
  w = struct('r', 4, 'zz', 0.01, 'zp', 0.04, 'a', 0, 'wz2', 6, 'zz2', 0.01, 'w2', 12, 'z2', 0.02, ...
             'w0S', 1, 'w0T', 4, 'xv', 0.8, 'Ms', 1.5, 'Mt', 1.5, 'active', m.active);
  P = two_mode_plant(m.active, w.r, w.zz, w.zp, w.wz2, w.zz2, w.w2, w.z2, w.w0S, w.w0T, w.xv, w.Ms, w.Mt);
  cases{end+1} = struct('name', m.name, 'P', P, 'nmeas', 1, 'ncon', 1, 'weights', w);
end

vel = {struct('name', 'velocity_r2', 'r', 2, 'zz', 0.01, 'zp', 0.02, 'a', 0, 'w0S', 0.5, 'w0T', 2, 'xv', 0.8, 'Ms', 1.5, 'Mt', 1.5), ...
       struct('name', 'velocity_r3_slow', 'r', 3, 'zz', 0.01, 'zp', 0.03, 'a', 0, 'w0S', 0.05, 'w0T', 3, 'xv', 0.8, 'Ms', 1.5, 'Mt', 1.5), ...
       struct('name', 'velocity_r4_friction', 'r', 4, 'zz', 0.02, 'zp', 0.1, 'a', 0.05, 'w0S', 0.8, 'w0T', 8, 'xv', 0.7071, 'Ms', 1.5, 'Mt', 1.8)};
for i = 1:numel(vel)
  v = vel{i};
  P = velocity_plant(v.r, v.zz, v.zp, v.a, v.w0S, v.w0T, v.xv, v.Ms, v.Mt);
  cases{end+1} = struct('name', v.name, 'P', P, 'nmeas', 1, 'ncon', 1, 'weights', v);
end

pos = struct('name', 'position_r3', 'r', 3, 'zz', 0.01, 'zp', 0.03, 'a', 0, 'w0S', 0.4, 'w0T', 3, 'xv', 0.8, 'Ms', 1.5, 'Mt', 1.5);
P = position_plant(pos.r, pos.zz, pos.zp, pos.a, pos.w0S, pos.w0T, pos.xv, pos.Ms, pos.Mt);
cases{end+1} = struct('name', pos.name, 'P', P, 'nmeas', 1, 'ncon', 1, 'weights', pos);

% A 2x2-exogenous MIMO problem with every block of D11 non-zero, D22 != 0 and an unstable A
% (fixed numbers): exercises the general formulas (D1111 non-empty), not only mixed sensitivity.
A = [0.5 1 0 0; -1 -0.2 0.3 0; 0 0 -2 1; 0.2 0 0 -1];
B1 = [1 0; 0 0.5; 0.3 0; 0 1];
B2 = [0; 1; 0; 0.5];
C1 = [1 0 0.5 0; 0 0 0 0.2];
C2 = [0 1 0 1];
D11 = [0.1 0.2; 0.05 0.3];
D12 = [0.3; 1];
D21 = [0.2 1];
D22 = 0.4;
P = ss(A, [B1 B2], [C1; C2], [D11 D12; D21 D22]);
cases{end+1} = struct('name', 'mimo_general', 'P', P, 'nmeas', 1, 'ncon', 1, 'weights', struct());

% Feasible: SB10FD finds a central controller for gamma and the closed loop is stable below gamma.
function ok = feasible(P, nmeas, ncon, g)
  try
    [~, N] = hinfsyn(P, nmeas, ncon, 'method', 'suboptimal', 'gmax', g);
    ok = isstable(N) && norm(N, inf, 1e-12) < g;
  catch
    ok = false;
  end
end

function g = optimal_gamma(P, nmeas, ncon)
  [~, ~, g0] = hinfsyn(P, nmeas, ncon, 'method', 'optimal', 'tolgam', 1e-2);
  hi = 1.5 * g0; lo = 0.5 * g0;
  assert(feasible(P, nmeas, ncon, hi) && ~feasible(P, nmeas, ncon, lo));
  while hi / lo > 1 + 1e-8
    mid = sqrt(lo * hi);
    if feasible(P, nmeas, ncon, mid), hi = mid; else, lo = mid; end
  end
  g = hi;
end

% JSON text with every number at full precision. Octave 7.3's jsonencode wrote
% -0.99999999999999989 as 0 (found on velocity_r3_slow's C matrix), so numbers are printed here.
function t = enc(v)
  if isstruct(v)
    keys = fieldnames(v);
    parts = cellfun(@(k) sprintf('"%s": %s', k, enc(v.(k))), keys, 'UniformOutput', false);
    t = ['{' strjoin(parts', ', ') '}'];
  elseif iscell(v)
    t = ['[' strjoin(cellfun(@enc, v, 'UniformOutput', false), ', ') ']'];
  elseif ischar(v)
    t = ['"' strrep(v, '"', '\"') '"'];
  elseif isscalar(v)
    t = sprintf('%.17g', double(v));
  elseif rows(v) == 1 || columns(v) == 1
    t = ['[' strjoin(arrayfun(@(x) sprintf('%.17g', x), v(:)', 'UniformOutput', false), ', ') ']'];
  else
    t = ['[' strjoin(arrayfun(@(i) enc(v(i, :)), 1:rows(v), 'UniformOutput', false), ', ') ']'];
  end
end

omega = logspace(-2, 2, 17);
out = {};
for i = 1:numel(cases)
  cs = cases{i};
  [a, b, c, d] = ssdata(cs.P);
  gopt = optimal_gamma(cs.P, cs.nmeas, cs.ncon);
  gsub = 1.2 * gopt;
  [K, N, gk] = hinfsyn(cs.P, cs.nmeas, cs.ncon, 'method', 'suboptimal', 'gmax', gsub);
  H = freqresp(K, omega);
  entry = struct('name', cs.name, 'states', rows(a), 'inputs', columns(b), 'outputs', rows(c), ...
                 'A', a, 'B', b, 'C', c, 'D', d, 'nmeas', cs.nmeas, 'ncon', cs.ncon, ...
                 'gamma_optimal', gopt, 'gamma_suboptimal', gsub, 'closed_loop_norm', norm(N, inf, 1e-12), ...
                 'controller_order', rows(K.a), 'omega', omega, 'K_re', real(H(:))', 'K_im', imag(H(:))', ...
                 'weights', cs.weights);
  out{end+1} = entry;
  printf('%s: order %d, gamma_opt %.9g, closed loop %.9g at %.4g\n', cs.name, rows(a), gopt, norm(N, inf, 1e-12), gsub);
end

doc = struct('generator', 'tools/reference/hinf_reference.m', ...
             'octave', version(), 'control', pkg('describe', 'control'){1}.version, ...
             'note', 'K_re/K_im: the SUBOPTIMAL controller at gamma_suboptimal, one SISO value per omega', ...
             'cases', {out});
fid = fopen('tests/data/core/hinf_reference.json', 'w');
fputs(fid, enc(doc));
fclose(fid);
printf('wrote tests/data/core/hinf_reference.json\n');
