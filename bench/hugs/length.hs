-- length of a long range, consumed as it is produced (bench/interp.sh)
main = print (length [1 .. 1000000])
