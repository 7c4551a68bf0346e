# Flash and static RAM budgets of the firmware image (issue 3) and the chip's hard limits. Read by
# the AVR build (which prints the figures after every link, warns when over budget and fails
# when the image cannot fit the chip) and by the host build's ctest FirmwareSize.ImageFitsTheChip.
# The budgets are targets tracked in docs/benchmarks.md and docs/firmware.md.
set(LL_FLASH_BUDGET 16384 CACHE STRING "Flash budget of lowlevel.elf, bytes (issue 3)")
set(LL_RAM_BUDGET 1536 CACHE STRING "Static RAM budget (.data + .bss + .noinit), bytes (issue 3)")
# ATmega328P: 32 KiB of flash less the Uno's 512-byte bootloader, 2 KiB of RAM. (Raised only for
# measurement builds linked with a larger text region: -Wl,--defsym=__TEXT_REGION_LENGTH__=...)
set(LL_CHIP_FLASH 32256 CACHE STRING "Flash available to the image on the chip, bytes")
set(LL_CHIP_RAM 2048 CACHE STRING "RAM of the chip, bytes")
