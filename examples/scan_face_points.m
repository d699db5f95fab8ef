function [points, occupancy, surface] = scan_face_points(msg)
% SCAN_FACE_POINTS  World points of a compact face-scan message.
%   [POINTS, OCCUPANCY, SURFACE] = SCAN_FACE_POINTS(MSG) turns a
%   sandbox_msgs.scan_face_compact_t (as lcm.jar delivers it, or any struct
%   with its fields) into an n^2 x 3 matrix of world points, row r and column
%   c of the face at index r * n + c + 1 (the hit, or the ray's end when free;
%   NaN where not scanned yet or for a hit beyond the millimetre range), and
%   the occupancy per point (-1 not scanned, 0 free, 1 occupied), and the
%   surface id of what each point hit (0: nothing; the names come on
%   <ROBOT>/WORLD), or an empty matrix when the message has no id plane. The grid and
%   the codes are those of bridge/lcmtypes/scan_face_compact_t.lcm; the C++
%   twin is sandbox::bridge::DecodeCompactFace (bridge/face_points.h).
n = double(msg.n);
E = double(msg.half_extent_m);
res = double(msg.resolution_m);
p = as_column(msg.sensor_position);
q = as_column(msg.box_orientation);
q = q / norm(q);
w = q(1); x = q(2); y = q(3); z = q(4);
R = [1 - 2 * (y^2 + z^2), 2 * (x * y - w * z), 2 * (x * z + w * y);
     2 * (x * y + w * z), 1 - 2 * (x^2 + z^2), 2 * (y * z - w * x);
     2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x^2 + y^2)];
f = double(msg.face);
a = zeros(3, 1);
a(floor(f / 2) + 1) = 1 - 2 * mod(f, 2);   % +X, -X, +Y, -Y, +Z, -Z
if f < 2
  u = [0; 1; 0]; v = [0; 0; 1];
elseif f < 4
  u = [1; 0; 0]; v = [0; 0; 1];
else
  u = [1; 0; 0]; v = [0; 1; 0];
end
[c, r] = meshgrid(0:n - 1, 0:n - 1);
c = reshape(c', [], 1);   % row by row: index r * n + c + 1
r = reshape(r', [], 1);
occupancy = ones(n * n, 1);
if double(msg.encoding) == 1
  code = as_column(msg.distance_mm);
  code(code < 0) = code(code < 0) + 65536;   % LCM's int16 carries unsigned millimetres
  d = code / 1000;
  d(code == 65535) = E;     occupancy(code == 65535) = 0;    % free
  d(code == 65534) = NaN;   occupancy(code == 65534) = -1;   % not scanned yet
  d(code == 65533) = NaN;                                    % a hit beyond 65.532 m
else
  d = as_column(msg.distance_m);
  occupancy(isinf(d)) = 0;   d(isinf(d)) = E;
  occupancy(isnan(d)) = -1;
end
starts = (-E + c * res) * (R * u)' + (-E + r * res) * (R * v)';
points = p' + starts + d .* (R * a)';
% The id plane: runs of one id in grid order.
runs = double(msg.num_runs);
surface = [];
if runs > 0
  ids = as_column(msg.run_surface);
  lengths = as_column(msg.run_length);
  surface = repelem(ids, lengths);
end
end

function values = as_column(field)
% A message field as a double column, whether Octave or MATLAB hands over a
% Java array or a numeric one.
if isjava(field)
  count = numel(field);
  values = zeros(count, 1);
  for i = 1:count
    values(i) = double(field(i));
  end
else
  values = double(field(:));
end
end
