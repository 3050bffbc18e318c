#include <stdio.h>
#include "zonetrace/zonetrace.h"
int main(void) { printf("zonetrace %s\n", zt_version()); return 0; }
