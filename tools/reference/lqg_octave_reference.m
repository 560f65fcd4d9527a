% Reference gains for tuning/lqg (the LQG compensators of catalog C7.13 and C7.17) from GNU Octave's
% control package: the regulator gain K from lqr(A, B, Q, R) and the Kalman gain L from
% lqe(A, G, C, W, V) (both SLICOT's Riccati solvers), with the closed-loop poles each returns. The
% issue asks for the full-order designs side by side with Octave's lqr and kalman; the scipy
% reference (tuning_lqg_reference.py) checks the rest of the compensator.
%
% The models are written out here from the equations of motion of the normalized two-mass plant
% (Im = 1, omega_z = 1; Il = k = r^2 - 1, b = 2 zeta_z (r^2 - 1); motor and load viscous frictions
% bm, bl; the load torque opposes the motion), independently of the C++ code:
%   w_m' = -(b + bm) w_m + b w_l - Ts + Tm,  Il w_l' = b w_m - (b + bl) w_l + Ts - Tl,
%   Ts' = k (w_m - w_l).
% Velocity LQG: x = [w_m w_l Ts xi], xi' = -w_m, Q = diag(0, 20, kbw/c^2, 20), R = kbw/c^2,
% c = r^2/2; estimator on [w_m w_l Ts Tl] (Tl constant), y = w_m, G = [e1 e4], W = I2, V = 0.1.
% Load-side LQG (C7.17): xi' = -w_l, the same weights; y = [w_m; w_l], V = 0.1 I2.
% Position LQG: x = [phi_m w_m phi_l w_l xi], xi' = -phi_m, Q = diag(1, 1, 20, 20, 5),
% R = kbw/c^2; estimator on [phi_m w_m phi_l w_l Tl], y = phi_m, G = I5, W = I5, V = 0.01.
%
% Run from the repository root:
%   octave --no-gui --quiet tools/reference/lqg_octave_reference.m
% Writes tests/data/tuning/lqg_octave_reference.json.
pkg load control

function [ap, bu, bt] = velocity_plant(r, zz, bm, bl)
  il = r^2 - 1; k = il; b = 2*zz*il;
  ap = [-(b + bm), b, -1; b/il, -(b + bl)/il, 1/il; k, -k, 0];
  bu = [1; 0; 0];
  bt = [0; -1/il; 0];
end

function c = velocity_case(r, zz, kbw, bm, bl, integral_on_load)
  [ap, bu, bt] = velocity_plant(r, zz, bm, bl);
  rho = kbw/(r^2/2)^2;
  aa = zeros(4); aa(1:3, 1:3) = ap;
  aa(4, 1 + integral_on_load) = -1;
  ba = [bu; 0];
  [K, ~, lqr_poles] = lqr(aa, ba, diag([0, 20, rho, 20]), rho);
  ae = [ap, bt; zeros(1, 4)];
  g = [1 0; 0 0; 0 0; 0 1];
  if integral_on_load
    ce = [1 0 0 0; 0 1 0 0];
    v = 0.1*eye(2);
  else
    ce = [1 0 0 0];
    v = 0.1;
  end
  [L, ~, kf_poles] = lqe(ae, g, ce, eye(2), v);
  c = struct('r', r, 'zeta_z', zz, 'kbw', kbw, 'bm', bm, 'bl', bl, 'K', K, 'L', L, ...
             'lqr_poles', lqr_poles, 'kf_poles', kf_poles);
end

function c = position_case(r, zz, kbw, bm, bl)
  il = r^2 - 1; k = il; b = 2*zz*il;
  ap = [0, 1, 0, 0; -k, -(b + bm), k, b; 0, 0, 0, 1; k/il, b/il, -k/il, -(b + bl)/il];
  bu = [0; 1; 0; 0];
  bt = [0; 0; 0; -1/il];
  rho = kbw/(r^2/2)^2;
  aa = [ap, zeros(4, 1); -1, 0, 0, 0, 0];
  ba = [bu; 0];
  [K, ~, lqr_poles] = lqr(aa, ba, diag([1, 1, 20, 20, 5]), rho);
  ae = [ap, bt; zeros(1, 5)];
  [L, ~, kf_poles] = lqe(ae, eye(5), [1 0 0 0 0], eye(5), 0.01);
  c = struct('r', r, 'zeta_z', zz, 'kbw', kbw, 'bm', bm, 'bl', bl, 'K', K, 'L', L, ...
             'lqr_poles', lqr_poles, 'kf_poles', kf_poles);
end

% JSON text with every number at full precision (jsonencode of Octave 7.3 rounds to 15 digits).
function t = num(x)
  t = sprintf('%.17g', x);
end
function t = vec(x)
  x = x(:).';
  t = ['[', strjoin(arrayfun(@num, x, 'UniformOutput', false), ', '), ']'];
end
function t = mat(m)
  rows = arrayfun(@(i) vec(m(i, :)), 1:rows(m), 'UniformOutput', false);
  t = ['[', strjoin(rows, ', '), ']'];
end
function t = roots_json(p)
  p = p(:);
  [~, order] = sortrows([round(abs(p)*1e9), -imag(p)]);
  p = p(order);
  items = arrayfun(@(z) ['[', num(real(z)), ', ', num(imag(z)), ']'], p, 'UniformOutput', false);
  t = ['[', strjoin(items.', ', '), ']'];
end
function t = case_json(c)
  t = sprintf('{"r": %s, "zeta_z": %s, "kbw": %s, "bm": %s, "bl": %s, "K": %s, "L": %s, "lqr_poles": %s, "kf_poles": %s}', ...
              num(c.r), num(c.zeta_z), num(c.kbw), num(c.bm), num(c.bl), vec(c.K), mat(c.L), ...
              roots_json(c.lqr_poles), roots_json(c.kf_poles));
end
function t = list_json(cases)
  t = ['[', strjoin(cellfun(@case_json, cases, 'UniformOutput', false), ', '), ']'];
end

% E29 (r = 3, zeta_z = 0.01, kbw = 1), C7.13's kbw sweep, and a plant with viscous frictions.
velocity = {velocity_case(3, 0.01, 1, 0, 0, 0), velocity_case(3, 0.01, 0.1, 0, 0, 0), ...
            velocity_case(2, 0.01, 10, 0, 0, 0), velocity_case(5, 0.02, 1, 0.05, 0.1, 0)};
load_side = {velocity_case(3, 0.01, 1, 0, 0, 1), velocity_case(5, 0.02, 0.3, 0.05, 0.1, 1)};
position = {position_case(3, 0.01, 1, 0, 0), position_case(2, 0.02, 0.3, 0.05, 0.1)};

fid = fopen('tests/data/tuning/lqg_octave_reference.json', 'w');
fprintf(fid, '{"generator": "tools/reference/lqg_octave_reference.m (GNU Octave %s, control %s: lqr, lqe)",\n', ...
        version(), pkg('describe', 'control'){1}.version);
fprintf(fid, ' "velocity": %s,\n "load_side": %s,\n "position": %s}\n', list_json(velocity), ...
        list_json(load_side), list_json(position));
fclose(fid);
