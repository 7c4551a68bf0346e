// Placeholder firmware entry point (replaced by the firmware issue).
#include <avr/io.h>

int main() {
    for (;;) {
    }
}
