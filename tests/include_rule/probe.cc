// Compiled by tests/include_rule: includes one header, PROBE_HEADER, with the
// include path of the module it is built against.
#include PROBE_HEADER

int main() { return 0; }
