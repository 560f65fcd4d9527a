% Reference values for core/model_reduction (balanced truncation), from GNU Octave's control
% package (hsvd; btamodred with the square-root method, which calls SLICOT AB09ID).
% Run from the repository root:
%   octave --no-gui --quiet tools/reference/model_reduction_reference.m
% Writes tests/data/core/model_reduction_reference.json.
pkg load control

cases = {};

% Three lightly damped modes (a multi-mode drive, C7.16): 6 states, SISO.
w = [1 5 20]; z = [0.05 0.03 0.02]; k = [1 0.3 0.1];
G = tf(0);
for i = 1:3
  G = G + tf(k(i) * w(i)^2, [1 2*z(i)*w(i) w(i)^2]);
end
G = ss(G);
cases{end+1} = struct('name', 'three_modes', 'sys', G, 'orders', [2 4]);

% Two-mass drive with viscous friction on both sides (stable): states motor speed, load speed,
% shaft twist; input motor torque, output motor speed (normalized: Jm = 1, antiresonance 1, r = 3).
r = 3; Jm = 1; Jl = r^2 - 1; c = Jl; d = 0.02; bm = 0.05; bl = 0.1;
A = [-(bm + d)/Jm, d/Jm, -c/Jm; d/Jl, -(bl + d)/Jl, c/Jl; 1, -1, 0];
B = [1/Jm; 0; 0]; C = [1 0 0]; D = 0;
cases{end+1} = struct('name', 'two_mass', 'sys', ss(A, B, C, D), 'orders', [1 2]);

% A stable 2x2 MIMO system with a feedthrough, 5 states (fixed numbers).
A = [-1 2 0 0 0; -2 -1 0 0 0; 0 0 -3 1 0; 0 0 0 -3 0.5; 0 0 0 0 -10];
B = [1 0; 0.5 1; 0 1; 1 0.2; 0.3 0.7];
C = [1 0 1 0 0.5; 0 1 0 0.3 1];
D = [0 0.1; 0 0];
cases{end+1} = struct('name', 'mimo', 'sys', ss(A, B, C, D), 'orders', [2 3]);

% The reduced-order H-infinity controller printed for the flexible frame (catalog C7.19):
% K(s) = -0.067 (s - 146)(s + 0.27)(s^2 + 0.52 s + 2.02) / (s (s^2 - 0.96 s + 2.9)(s^2 + 22.35 s + 274.2)),
% with an integrator and an unstable pair: btamodred keeps the 3 poles right of its default
% boundary -sqrt(eps) and reduces the stable pair.
K = zpk([146; -0.27; roots([1 0.52 2.02])], [0; roots([1 -0.96 2.9]); roots([1 22.35 274.2])], -0.067);
K = ss(K);
cases{end+1} = struct('name', 'c7_19_controller', 'sys', K, 'orders', [3 4], 'unstable', 3);

% The same controller in series with two lightly damped stable modes (9 states, 6 stable).
M = tf([1 0.2 9], [1 0.6 9]) * tf([1 0.4 40], [1 2 40]);
cases{end+1} = struct('name', 'unstable_with_modes', 'sys', ss(K * M), 'orders', [4 5 7], 'unstable', 3);

omega = logspace(-1, 2, 13);
out = {};
for i = 1:numel(cases)
  cs = cases{i};
  [a, b, cc, dd] = ssdata(cs.sys);
  if isfield(cs, 'unstable')
    % hsvd of an unstable system gives its stable part's values (unstable ones reported as Inf).
    hsv = hsvd(cs.sys);
    hsv = hsv(isfinite(hsv))';
    unstable = cs.unstable;
  else
    hsv = hsvd(cs.sys)';
    unstable = 0;
  end
  entry = struct('name', cs.name, 'A', a, 'B', b, 'C', cc, 'D', dd, 'hsv', hsv, 'unstable', unstable, ...
                 'states', size(a, 1), 'omega', omega);
  reduced = {};
  for nr = cs.orders
    Gr = btamodred(cs.sys, nr, 'method', 'sr');
    H = freqresp(Gr, omega);  % outputs x inputs x frequencies
    entry_r = struct('order', nr, 're', real(H(:))', 'im', imag(H(:))', 'outputs', size(H, 1), 'inputs', size(H, 2));
    reduced{end+1} = entry_r;
  end
  entry.reduced = reduced;
  out{end+1} = entry;
end

doc = struct('generator', 'tools/reference/model_reduction_reference.m', ...
             'octave', version(), 'control', pkg('describe', 'control'){1}.version, ...
             'note', 'H(:) is column-major over (output, input, frequency)', 'cases', {out});
fid = fopen('tests/data/core/model_reduction_reference.json', 'w');
fputs(fid, jsonencode(doc));
fclose(fid);
printf('wrote tests/data/core/model_reduction_reference.json\n');
