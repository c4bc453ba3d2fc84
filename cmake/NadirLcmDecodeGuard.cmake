# cmake -DHEADER=<generated .hpp> -P NadirLcmDecodeGuard.cmake
#
# LCM 1.3.1's generated decode() sizes a vector from the message's own count
# before checking that the bytes left can hold that many elements, and takes a
# string's length less one without checking it is at least 1: a datagram that
# claims 2^31 elements makes the receiver allocate gigabytes, and one that claims
# an empty string throws std::length_error out of decode(). Every element takes
# at least one byte, so a count below 0 or above the bytes left is refused here
# the way LCM refuses any other malformed message: decode() returns -1.
file(READ "${HEADER}" text)
string(REGEX REPLACE
  "\n([ ]*)this->([A-Za-z0-9_]+)\\.resize\\(this->([A-Za-z0-9_]+)\\);"
  "\n\\1if(this->\\3 < 0 || this->\\3 > maxlen - pos) return -1;\n\\1this->\\2.resize(this->\\3);"
  text "${text}")
string(REGEX REPLACE
  "if\\((__[A-Za-z0-9_]+) > maxlen - pos\\) return -1;"
  "if(\\1 < 1 || \\1 > maxlen - pos) return -1;"
  text "${text}")
file(WRITE "${HEADER}" "${text}")
