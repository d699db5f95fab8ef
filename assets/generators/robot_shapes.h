#pragma once
// Dimensions of the bundled robots (assets/generators/robots.cc writes them;
// tests compare poses against chains built from these numbers).
// Robot frame: x forward, y left, z up, metres.

namespace sandbox::assets::robots {

// The flexible flying wing (ELAHA-like): bone 0 "root" spans the centre
// section |y| < kCentreHalfWidth; right bones 1-10 "R1".."R10" and left bones
// 11-20 "L1".."L10" follow outwards, each kElementLength long, joint i at
// |y| = kCentreHalfWidth + (i - 1) kElementLength; bones 21-23 "E1".."E3" are
// elevators hinged at the trailing edge of the centre section.
constexpr double kCentreHalfWidth = 0.6;
constexpr double kElementLength = 1.2;
constexpr int kElementsPerHalf = 10;
constexpr double kHalfSpan = kCentreHalfWidth + kElementsPerHalf * kElementLength;  // 12.6 m
constexpr double kLeadingEdgeX = 0.35;
constexpr double kTrailingEdgeX = -0.65;
constexpr double kThickness = 0.12;
constexpr double kBlendHalfWidth = 0.1;  // vertices within this of a joint blend both bones
constexpr double kElevatorY[3] = {-0.4, 0.0, 0.4};
constexpr double kElevatorWidth = 0.35;
constexpr double kElevatorChord = 0.25;

// The 6-axis arm: joint k sits kArmOffsetsZ[k] above joint k-1 (joint 1 above
// the base origin) and turns about kArmAxes[k]; the tool point is kToolZ above joint 6.
constexpr double kArmOffsetsZ[6] = {0.25, 0.2, 0.6, 0.5, 0.15, 0.1};
constexpr char kArmAxes[6] = {'z', 'y', 'y', 'z', 'y', 'z'};
constexpr double kToolZ = 0.08;

// The quadrotor ("+" layout): rotors 1-4 at (r, 0), (0, r), (-r, 0), (0, -r) with
// r = kRotorOffset, kRotorZ above the body origin, spinning about z.
constexpr double kRotorOffset = 0.2;
constexpr double kRotorZ = 0.05;

}  // namespace sandbox::assets::robots
