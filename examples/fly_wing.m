% An external model in MATLAB or Octave, over LCM through lcm.jar: flies the
% bundled flying wing (ELAHA) in a circle 60 m above the sample level and bends
% its wings, like examples/fly_wing.cc. Run from the repository root:
%
%   octave --no-gui examples/fly_wing.m [DURATION_S] [hover]
%
% "hover" holds the wing at (12, 34, 56) instead (the tests use it). In MATLAB,
% set the two variables below and run the file. The types jar is
% build/sandbox_msgs.jar, or the one the environment variable SANDBOX_MSGS_JAR
% names (a build in another folder).
args = argv();
duration_s = 10;
hover = false;
if numel(args) >= 1, duration_s = str2double(args{1}); end
if numel(args) >= 2, hover = strcmp(args{2}, 'hover'); end

javaaddpath('/usr/share/java/lcm.jar');      % Debian's liblcm-java
types_jar = getenv('SANDBOX_MSGS_JAR');
if isempty(types_jar), types_jar = fullfile(pwd, 'build', 'sandbox_msgs.jar'); end
javaaddpath(types_jar);                      % the sandbox's types
lc = javaMethod('getSingleton', 'lcm.lcm.LCM');   % LCM's default URL

rate_hz = 100;
steps = round(duration_s * rate_hz);
t0 = tic;
for k = 0:steps - 1
  t = k / rate_hz;
  pose = javaObject('sandbox_msgs.robot_pose_t');
  pose.utime = int64(round(1e6 * time()));
  pose.seq = int64(k);
  if hover
    position = [12; 34; 56];
    yaw = 0;
  else
    a = 15 / 120 * t;
    position = [120 * cos(a); 120 * sin(a); 60 + 5 * sin(0.3 * t)];
    yaw = a + pi / 2;
  end
  pose.position = position;
  pose.orientation = [cos(yaw / 2); 0; 0; sin(yaw / 2)];   % w, x, y, z
  lc.publish('ELAHA/POSE', pose);

  bones = javaObject('sandbox_msgs.bone_values_t');
  bones.utime = pose.utime;
  bones.seq = pose.seq;
  bones.num_values = int32(45);
  values = zeros(45, 1);
  bend = 0.06 * sin(1.5 * t);
  values(2 * (1:10) + 1) = bend;      % right wing rolls (bone b's first value is 2b, 0-based)
  values(2 * (11:20) + 1) = -bend;    % left wing
  bones.values = values;
  lc.publish('ELAHA/BONES', bones);

  pause(max(0, (k + 1) / rate_hz - toc(t0)));
end
printf('fly_wing.m: published %d poses\n', steps);
