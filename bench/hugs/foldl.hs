-- a strict left fold over a range: qcs's foldl is strict in the
-- accumulator, so Hugs runs foldl' (its lazy foldl overflows the stack)
import Data.List (foldl')
main = print (foldl' (+) 0 [1 .. 1000000])
