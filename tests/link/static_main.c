/* Calls the two translation units built from static_unit.c. */
int static_unit_a(void);
int static_unit_b(void);

int main(void) {
    return static_unit_a() + static_unit_b() ? 1 : 0;
}
