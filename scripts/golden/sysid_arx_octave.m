% Golden values for the ARX estimator: octave-control's arx (QR "square-root" least squares,
% control-3.4.0/arx.m) on a deterministic record.
%
% Run from the project root:  octave --no-gui -q scripts/golden/sysid_arx_octave.m
% Writes host/lib/sysid/testdata/arx_data.csv (t_s,u,y) and host/lib/sysid/testdata/arx_octave.json.
%
% Convention: octave-control's 'nk' is the number of samples of delay BEYOND the one sample every
% ARX regressor has (it pads B with 1 + nk zeros), i.e. MATLAB's and vibid's nk = octave nk + 1.
% Regression rows then agree when na <= nb + octave_nk (octave drops max(na, nb) + nk rows; vibid and
% MATLAB drop max(na, nk + nb - 1)), which all cases below satisfy or have octave nk = 0.
pkg load control

n = 600;
dt = 0.01;
% Deterministic pseudo-random binary input and noise (a linear congruential generator, so the
% record is reproducible without any random-number state).
state = 12345;
lcg = zeros(2 * n, 1);
for i = 1:2 * n
  state = mod(1103515245 * state + 12345, 2^31);
  lcg(i) = state / 2^31;
end
u = sign(lcg(1:n) - 0.5) + 0.3 * sin((0:n-1)' * 0.05);
e = lcg(n+1:end) - 0.5;
% True system: a lightly damped 2nd-order ZOH-sampled plant with coloured noise (not ARX).
y = filter([0 0.08 0.06], [1 -1.6 0.8], u) + filter([1 0.5], [1 -0.7], 0.02 * e);

cases = {[2 2 0], [4 3 0], [3 3 0], [2 3 1], [1 1 0]};
out = struct('na', {}, 'nb', {}, 'nk', {}, 'octave_nk', {}, 'A', {}, 'B', {});
for c = 1:numel(cases)
  na = cases{c}(1); nb = cases{c}(2); nk_oct = cases{c}(3);
  dat = iddata(y, u, dt);
  sys = arx(dat, 'na', na, 'nb', nb, 'nk', nk_oct);
  [num, den] = filtdata(sys(1, 1));
  out(c).na = na;
  out(c).nb = nb;
  out(c).nk = nk_oct + 1;
  out(c).octave_nk = nk_oct;
  out(c).A = den{1}(:)';
  out(c).B = num{1}(:)';
end

root = fullfile(fileparts(mfilename('fullpath')), '..', '..');
testdata = fullfile(root, 'host', 'lib', 'sysid', 'testdata');
fid = fopen(fullfile(testdata, 'arx_data.csv'), 'w');
fprintf(fid, 't_s,u,y\n');
fprintf(fid, '%.17g,%.17g,%.17g\n', [(0:n-1)' * dt, u, y]');
fclose(fid);
fid = fopen(fullfile(testdata, 'arx_octave.json'), 'w');
fprintf(fid, '%s\n', jsonencode(struct('source', 'octave-control 3.4.0 arx', 'cases', out)));
fclose(fid);
